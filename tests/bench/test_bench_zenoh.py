"""The bench's zenoh part, path by path: each pair of processes (aiorobot, bare zenoh-python, bare
zenoh-python into an asyncio loop, and with iceoryx2 installed its two paths) carries small
messages, images and a burst, and reports what it measured; the receiver's record loses no count
to a report taken while another thread records."""

from __future__ import annotations

import json
import threading

import pytest

from aiorobot.bench._zenoh import _Peer, _Record, _round, _warm_up, available_paths
from tests.transport.conftest import router_port  # noqa: F401 - the transport tests' router fixture

pytestmark = pytest.mark.timeout(90)
_PATHS = [p for p, why in available_paths().items() if why is None and p != "dora-rs"]  # dora: test_bench_dora.py


@pytest.mark.parametrize("path", _PATHS)
def test_each_path_carries_small_messages_images_and_a_burst(path: str, router_port: int) -> None:
    recv, send = _Peer("recv", path, router_port), _Peer("send", path, router_port)
    try:
        assert recv.ready() is None
        assert send.ready() is None
        _warm_up(recv, send)
        got: dict = {"small": [], "image": [], "burst": [], "small_sent": 0, "image_sent": 0, "small_cost": [], "image_cost": []}
        _round(recv, send, got, n_small=100, n_image=5, n_burst=500)
    finally:
        send.close()
        recv.close()
    assert recv.proc.returncode == 0 and send.proc.returncode == 0
    assert got["small_sent"] == 100 and got["image_sent"] == 5
    assert len(got["small_cost"]) == 100 and len(got["image_cost"]) == 5  # one timed send call per message
    assert all(c > 0 for c in got["small_cost"] + got["image_cost"])
    # what arrived (a loaded machine may drop some of a best-effort path; never more than was sent)
    assert 0 < len(got["small"]) <= 100 and 0 < len(got["image"]) <= 5
    assert all(lat > 0 for lat in got["small"] + got["image"])  # one-way, stamped by the sender
    (burst,) = got["burst"]
    assert burst["sent"] == 500 and 0 < burst["received"] <= 500 and burst["last"] >= burst["first"] > 0
    assert set(burst["cpu_sec"]) == {"zenoh", "other"} and min(burst["cpu_sec"].values()) >= 0  # (Linux: /proc)


def test_process_cpu_counts_what_the_process_used_and_none_for_no_process() -> None:
    import os
    import subprocess
    import sys
    import time

    from aiorobot.bench._zenoh import _process_cpu

    before = _process_cpu(os.getpid())
    start = time.process_time()
    while time.process_time() - start < 0.3:  # 0.3 s of this process's CPU, whatever the wall clock
        pass
    after = _process_cpu(os.getpid())
    assert before is not None and after is not None
    assert after["other"] - before["other"] >= 0.2  # (this thread is no zenoh thread)
    gone = subprocess.Popen([sys.executable, "-c", "pass"])
    gone.wait()
    assert _process_cpu(gone.pid) is None


def test_a_report_taken_while_threads_record_loses_no_count() -> None:
    rec = _Record()
    per_thread, threads = 20_000, 4
    reports: list[dict] = []
    done = threading.Event()

    def record(kind: int) -> None:
        for i in range(per_thread):
            rec.got(kind, i)

    def report() -> None:
        while not done.is_set():
            reports.append(json.loads(rec.report()))

    reporter = threading.Thread(target=report)
    reporter.start()
    workers = [threading.Thread(target=record, args=(k % 2,)) for k in range(threads)]
    for w in workers:
        w.start()
    for w in workers:
        w.join()
    done.set()
    reporter.join()
    reports.append(json.loads(rec.report()))
    assert sum(len(r["lat"]["small"]) for r in reports) == per_thread * threads // 2
    assert sum(r["burst"]["n"] for r in reports) == per_thread * threads // 2
