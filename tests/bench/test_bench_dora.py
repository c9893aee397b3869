"""The bench's dora-rs path: a dora coordinator, daemon and dataflow of the bench's own, the bench's
sender and receiver processes joined to it as dynamic nodes, and nothing of dora left running after,
also when a peer dies first. Skipped where dora-rs (and its CLI) is not installed."""

from __future__ import annotations

import importlib.util
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest

from aiorobot.bench._dora import DoraDataflow, _error_line, dora_cli
from aiorobot.bench._zenoh import _Peer, _round, _warm_up

pytestmark = pytest.mark.timeout(60)
_MISSING = (
    "dora-rs not installed (pip install dora-rs)" if importlib.util.find_spec("dora") is None
    else "the dora CLI not installed (pip install dora-rs-cli)" if dora_cli() is None
    else None
)
needs_dora = pytest.mark.skipif(_MISSING is not None, reason=_MISSING or "")


def _dora_processes(port: int) -> list[str]:
    """Command lines of live processes that name ``port`` and dora (daemon, coordinator, nodes)."""
    found = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            cmd = (entry / "cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
        except OSError:
            continue
        if str(port) in cmd and ("dora" in cmd or "aiorobot.bench" in cmd):
            found.append(cmd)
    return found


def _start_pair(flow: DoraDataflow) -> tuple[_Peer, _Peer]:
    recv, send = _Peer("recv", "dora-rs", flow.daemon_port), _Peer("send", "dora-rs", flow.daemon_port)
    assert recv.ready() is None
    assert send.ready() is None
    return recv, send


@needs_dora
def test_dora_path_carries_small_messages_images_and_a_burst_then_leaves_nothing_running() -> None:
    flow = DoraDataflow()
    with flow:
        pids = [p.pid for p in flow._procs]
        recv, send = _start_pair(flow)
        try:
            _warm_up(recv, send)
            got: dict = {"small": [], "image": [], "burst": [], "small_sent": 0, "image_sent": 0,
                         "small_cost": [], "image_cost": []}
            _round(recv, send, got, n_small=100, n_image=5, n_burst=200)
        finally:
            send.close()
            recv.close()
    # dora's inputs keep the newest 10 (its default queue_size): a stall of the receiver drops, so the
    # counts are bounded, not exact
    assert got["small_sent"] == 100 and 0 < len(got["small"]) <= 100
    assert got["image_sent"] == 5 and 0 < len(got["image"]) <= 5
    assert all(lat > 0 for lat in got["small"] + got["image"])
    assert got["burst"][0]["sent"] == 200 and 0 < got["burst"][0]["received"] <= 200
    assert [pid for pid in pids if os.path.exists(f"/proc/{pid}")] == []
    assert _dora_processes(flow.daemon_port) == []


@needs_dora
def test_a_dead_receiver_is_an_error_and_dora_still_shuts_down() -> None:
    flow = DoraDataflow()
    with flow:
        recv, send = _start_pair(flow)
        try:
            recv.proc.kill()
            recv.proc.wait()
            with pytest.raises(RuntimeError, match=r"^the dora-rs recv process ended \(exit status -9\)$"):
                recv.ask("report")
            assert send.ask("small 5")["sent"] == 5  # the sender goes on with its receiver gone
        finally:
            send.close()
            recv.close()
    assert _dora_processes(flow.daemon_port) == []


@needs_dora
def test_a_killed_bench_takes_its_dora_daemon_and_coordinator_with_it() -> None:
    script = (
        "import sys\n"
        "from aiorobot.bench._dora import DoraDataflow\n"
        "flow = DoraDataflow()\n"
        "flow.start()\n"
        "print(flow._dir.name, flow.daemon_port, *(p.pid for p in flow._procs), flush=True)\n"
        "sys.stdin.read()\n"
    )
    bench = subprocess.Popen([sys.executable, "-c", script], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    try:
        workdir, *numbers = bench.stdout.readline().split()
        port, *pids = (int(x) for x in numbers)
        assert len(pids) == 2 and all(os.path.exists(f"/proc/{pid}") for pid in pids)
    finally:
        bench.kill()
        bench.wait()
        bench.stdin.close()
        bench.stdout.close()
    deadline = time.monotonic() + 20
    while _dora_processes(port) and time.monotonic() < deadline:
        time.sleep(0.05)  # polling for the processes to end, bounded
    assert _dora_processes(port) == []
    shutil.rmtree(workdir)  # what a killed bench cannot remove itself


@needs_dora
def test_a_node_that_cannot_join_says_why_in_one_line() -> None:
    with DoraDataflow() as flow:
        wrong = _Peer("send", "dora-rs", flow.daemon_port + 1 if flow.daemon_port < 65535 else flow.daemon_port - 1)
        why = wrong.ready()
        wrong.close()
    assert why is not None and why.startswith("the dora-rs send process did not start (dora node 'sender' could not join")
    assert "\n" not in why


def test_a_dora_error_reads_as_one_line_with_its_causes() -> None:
    text = "\n[ERROR]\nno unnamed daemon connections\n\nLocation:\n    binaries/cli/src/common.rs:78:48\n"
    assert _error_line(text) == "no unnamed daemon connections"
    text = ("[ERROR]\nfailed to run dora-coordinator\n\nCaused by:\n   0: failed to start WS server\n"
            "   1: Address already in use (os error 98)\n\nLocation:\n    binaries/coordinator/src/ws_server.rs:282:20\n")
    assert _error_line(text) == "failed to run dora-coordinator: failed to start WS server: Address already in use (os error 98)"
    assert _error_line("") == "no output"
