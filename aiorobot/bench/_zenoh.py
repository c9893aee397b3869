"""``aiorobot bench latency`` zenoh rows: the same message pair through every path a Python robot
developer could pick, each a pair of processes, interleaved in one run.

Paths (each one a sender process and a receiver process of its own):

- ``aiorobot``: a Runtime with a ZenohTransport in each process (a Twist, a 640x480x3 Image);
- ``zenoh``: bare zenoh-python, the same session config (``build_session_config``: batching on,
  shared memory on, through the same router), ``put`` -> callback; the image put from a
  ``ShmProvider`` buffer;
- ``zenoh-loop``: the same bare pair, its receiver handing each sample to its asyncio (uvloop)
  loop with ``call_soon_threadsafe`` and stamping it there: the floor of any asyncio receiver,
  aiorobot's included;
- ``iceoryx2``: iceoryx2 pub/sub with an event to wake the receiver, when ``iceoryx2`` is
  importable; the image written once into a loaned sample;
- ``aiorobot-iox``: the ``aiorobot`` pair (domain 1, apart from it) with ``iceoryx2_topics=["*"]``:
  the image over iceoryx2 (``aiorobot.transport._iceoryx2``), when ``iceoryx2`` is importable;
  its small messages and bursts go over zenoh as the ``aiorobot`` pair's do, so the table leaves
  them out;
- ``dora-rs``: two dora-rs Python nodes, when ``dora`` is importable: the bench starts a dora
  coordinator, daemon and dataflow of its own and its sender and receiver join it as dynamic nodes
  (:mod:`aiorobot.bench._dora`).

The sender stamps each message with ``time.monotonic_ns()`` (one clock for every process of a Linux
host); the receiver reports one-way latency (receive minus stamp) and, for a burst sent back to
back, how many arrived and at what rate. Rounds go through the paths in turn, so the machine's
load falls on all of them alike; figures are pooled over the rounds.
"""

from __future__ import annotations

import asyncio
import contextlib
import json
import logging
import socket
import subprocess
import sys
import threading
import time
from typing import Any

__all__ = ["PATHS", "available_paths", "run", "table"]

PATHS = ("aiorobot", "zenoh", "zenoh-loop", "iceoryx2", "aiorobot-iox", "dora-rs")
SMALL_BYTES = 52  # a Twist's CDR
IMAGE_BYTES = 640 * 480 * 3
SMALL_HZ = 1000.0
IMAGE_HZ = 30.0
_SERVICE = "aiorobot/bench/zenoh"


def available_paths() -> dict[str, str | None]:
    """Each path, and why it cannot run here (None: it can)."""
    import importlib.util

    out: dict[str, str | None] = {"aiorobot": None, "zenoh": None, "zenoh-loop": None}
    out["iceoryx2"] = None if importlib.util.find_spec("iceoryx2") else "not installed (pip install iceoryx2)"
    out["aiorobot-iox"] = out["iceoryx2"]
    out["dora-rs"] = None if importlib.util.find_spec("dora") else "not installed (pip install dora-rs dora-rs-cli)"
    return out


# -- the peers (run as ``python -m aiorobot.bench._zenoh ROLE PATH PORT``) ------------------------------


class _Record:
    """What a receiver saw since its last report. ``got`` may run on a receiving thread (bare
    zenoh's callback, iceoryx2's and dora's pumps) while ``report`` runs on the loop: both hold
    the lock, so no message lands between a report and the reset that follows it."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self.lat, self.burst = self._fresh()

    @staticmethod
    def _fresh() -> tuple[dict[str, list[int]], dict[str, int]]:
        return {"small": [], "image": []}, {"n": 0, "first": 0, "last": 0}

    def got(self, kind: int, stamp: int) -> None:
        now = time.monotonic_ns()
        with self._lock:
            if kind == 1:
                b = self.burst
                b["n"] += 1
                b["first"] = b["first"] or now
                b["last"] = now
            else:
                self.lat["small" if kind == 0 else "image"].append(now - stamp)

    def report(self) -> str:
        with self._lock:
            lat, burst = self.lat, self.burst
            self.lat, self.burst = self._fresh()
        return json.dumps({"lat": lat, "burst": burst})


def _stamp_bytes(kind: int, size: int) -> bytes:
    return time.monotonic_ns().to_bytes(8, "little") + bytes((kind,)) + bytes(size - 9)


def _unstamp(data: Any) -> tuple[int, int]:
    return data[8], int.from_bytes(bytes(data[:8]), "little")


async def _aiorobot_receiver(port: int, iceoryx2: bool = False) -> None:
    """With ``iceoryx2``, the image over iceoryx2 (domain 1)."""
    from .. import Node, QoSProfile, Runtime
    from ..msgs.geometry_msgs import Twist
    from ..msgs.sensor_msgs import Image
    from ..transport import ZenohTransport

    rec = _Record()
    # what a burst loses (the sender's DROP congestion control) is the table's "% of" column, not a
    # warning line of the receiver's in the middle of the bench's output
    logging.getLogger("aiorobot.transport").setLevel(logging.ERROR)
    transport = ZenohTransport(domain_id=int(iceoryx2), connect=[f"tcp/127.0.0.1:{port}"], iceoryx2_topics=_iox(iceoryx2))
    async with Runtime(transport=transport, handle_signals=False) as rt:
        node = rt.add_node(Node("bench_sink"))
        node.create_subscription(Twist, "/bench/twist", lambda m: rec.got(int(m.linear.y), int(m.linear.x)), QoSProfile(depth=10))
        node.create_subscription(
            Image, "/bench/image",
            lambda m: rec.got(2, m.header.stamp.sec * 1_000_000_000 + m.header.stamp.nanosec), QoSProfile(depth=10),
        )
        await _serve_stdin(lambda cmd: rec.report())


async def _aiorobot_sender(port: int, iceoryx2: bool = False) -> None:
    import numpy as np

    from .. import Node, QoSProfile, Runtime
    from ..msgs.geometry_msgs import Twist, Vector3
    from ..msgs.sensor_msgs import Image
    from ..transport import ZenohTransport

    transport = ZenohTransport(domain_id=int(iceoryx2), connect=[f"tcp/127.0.0.1:{port}"], iceoryx2_topics=_iox(iceoryx2))
    async with Runtime(transport=transport, handle_signals=False) as rt:
        node = rt.add_node(Node("bench_source"))
        twist = node.create_publisher(Twist, "/bench/twist", QoSProfile(depth=10))
        image = node.create_publisher(Image, "/bench/image", QoSProfile(depth=10))
        data = np.zeros(IMAGE_BYTES, dtype=np.uint8)

        def small(kind: int) -> Twist:
            return Twist(linear=Vector3(x=float(time.monotonic_ns()), y=float(kind)))

        def picture() -> Image:
            msg = Image(height=480, width=640, encoding="rgb8", step=640 * 3, data=data)
            msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(time.monotonic_ns(), 1_000_000_000)
            return msg

        await _serve_stdin(_sender_commands((small, twist.publish), (picture, image.publish)))


def _iox(iceoryx2: bool) -> list[str]:
    """``iceoryx2_topics`` of an aiorobot peer: images over iceoryx2, or nothing (whatever the
    environment says)."""
    return ["*"] if iceoryx2 else []


async def _zenoh_receiver(port: int, service: str = _SERVICE, hop: bool = False) -> None:
    """Bare zenoh-python; with ``hop``, each sample is handed to the asyncio loop with
    ``call_soon_threadsafe`` and stamped there (the least any asyncio program pays)."""
    import zenoh

    from ..transport._zenoh import build_session_config

    rec = _Record()
    cfg, _ = build_session_config(connect=[f"tcp/127.0.0.1:{port}"])
    session = zenoh.open(cfg)
    loop = asyncio.get_running_loop()

    def on_sample(sample: Any) -> None:
        data = sample.payload.to_bytes()
        if hop:
            loop.call_soon_threadsafe(rec.got, *_unstamp(data))
        else:
            rec.got(*_unstamp(data))

    sub = session.declare_subscriber(f"{service}/*", on_sample)
    try:
        await _serve_stdin(lambda cmd: rec.report())
    finally:
        sub.undeclare()
        session.close()


async def _zenoh_sender(port: int, service: str = _SERVICE) -> None:
    import zenoh
    from zenoh.shm import GarbageCollect, ShmProvider

    from ..transport._zenoh import build_session_config

    cfg, _ = build_session_config(connect=[f"tcp/127.0.0.1:{port}"])
    session = zenoh.open(cfg)
    shm = ShmProvider.default_backend(48 * 1024 * 1024)
    pub = session.declare_publisher(f"{service}/small", congestion_control=zenoh.CongestionControl.DROP)
    img = session.declare_publisher(f"{service}/image", congestion_control=zenoh.CongestionControl.DROP)
    pixels = bytes(IMAGE_BYTES - 9)

    def picture() -> Any:  # the image written into a shared-memory buffer, as a zero-copy program does
        buf = shm.alloc(IMAGE_BYTES, GarbageCollect())
        buf[:9] = time.monotonic_ns().to_bytes(8, "little") + b"\x02"
        buf[9:] = pixels
        return buf

    try:
        await _serve_stdin(_sender_commands((lambda kind: _stamp_bytes(kind, SMALL_BYTES), pub.put), (picture, img.put)))
    finally:
        session.close()


async def _iceoryx2_receiver(port: int) -> None:
    import ctypes

    import iceoryx2 as iox2

    from ..transport._iceoryx2 import quiet

    quiet()

    rec = _Record()
    node = iox2.NodeBuilder.new().create(iox2.ServiceType.Ipc)
    subs = []
    for name in ("small", "image"):
        service = (
            node.service_builder(iox2.ServiceName.new(f"{_SERVICE}/{port}/{name}"))
            .publish_subscribe(iox2.Slice[ctypes.c_uint8])
            .subscriber_max_buffer_size(64)
            .open_or_create()
        )
        subs.append(service.subscriber_builder().buffer_size(64).create())
    event = node.service_builder(iox2.ServiceName.new(f"{_SERVICE}/{port}/event")).event().open_or_create()
    listener = event.listener_builder().create()
    stop = False

    def pump() -> None:
        while not stop:
            if not listener.timed_wait(iox2.Duration.from_millis(100)):
                continue
            for sub in subs:
                while (sample := sub.receive()) is not None:
                    view = sample.payload().as_memory_view().cast("B")
                    rec.got(*_unstamp(view))
                    del view, sample

    task = asyncio.ensure_future(asyncio.to_thread(pump))
    print("ready", flush=True)
    await _serve_stdin(lambda cmd: rec.report(), announce=False)
    stop = True
    await task


async def _iceoryx2_sender(port: int) -> None:
    import ctypes

    import iceoryx2 as iox2
    import numpy as np

    from ..transport._iceoryx2 import quiet

    quiet()

    node = iox2.NodeBuilder.new().create(iox2.ServiceType.Ipc)
    pubs = {}
    for name, size in (("small", SMALL_BYTES), ("image", IMAGE_BYTES)):
        service = (
            node.service_builder(iox2.ServiceName.new(f"{_SERVICE}/{port}/{name}"))
            .publish_subscribe(iox2.Slice[ctypes.c_uint8])
            .subscriber_max_buffer_size(64)
            .open_or_create()
        )
        pubs[name] = service.publisher_builder().initial_max_slice_len(size).max_loaned_samples(4).create()
    event = node.service_builder(iox2.ServiceName.new(f"{_SERVICE}/{port}/event")).event().open_or_create()
    notifier = event.notifier_builder().create()
    pixels = np.zeros(IMAGE_BYTES, dtype=np.uint8)

    def send(name: str, head: bytes, body: Any, size: int) -> None:
        sample = pubs[name].loan_slice_uninit(size)
        ptr = sample.payload().as_ptr()
        ctypes.memmove(ptr, head, len(head))
        if body is not None:
            ctypes.memmove(ptr + len(head), body.ctypes.data, size - len(head))
        sample.assume_init().send()
        notifier.notify()

    await _serve_stdin(_sender_commands(
        (lambda kind: _stamp_bytes(kind, SMALL_BYTES), lambda head: send("small", head, None, SMALL_BYTES)),
        (lambda: time.monotonic_ns().to_bytes(8, "little") + b"\x02", lambda head: send("image", head, pixels[9:], IMAGE_BYTES)),
    ))


def _sender_commands(small: tuple[Any, Any], picture: tuple[Any, Any]) -> Any:
    """A sender's command handler: ``small N`` at 1 kHz, ``image N`` at 30 Hz, ``burst N`` back to back.

    ``small`` is ``(make(kind), send(message))`` and ``picture`` ``(make(), send(image))``: the
    message is stamped and built by ``make``, and the send call timed is ``send`` alone (for
    aiorobot, ``publish()``; for bare zenoh, ``put()``)."""
    make_small, send_small = small

    async def handle(cmd: str) -> str:
        verb, count = cmd.split()
        n = int(count)
        start = time.perf_counter()
        if verb == "burst":
            for i in range(n):
                send_small(make_small(1))
                if i % 500 == 499:
                    await asyncio.sleep(0)  # a long burst must not read as a stalled loop
            return json.dumps({"sent": n, "send_sec": time.perf_counter() - start})
        period = 1.0 / (SMALL_HZ if verb == "small" else IMAGE_HZ)
        make, send = ((lambda: make_small(0)), send_small) if verb == "small" else picture
        cost: list[int] = []  # how long the send call itself takes (perf_counter_ns)
        for i in range(n):
            msg = make()
            t0 = time.perf_counter_ns()
            send(msg)
            cost.append(time.perf_counter_ns() - t0)
            del msg
            delay = start + (i + 1) * period - time.perf_counter()
            await asyncio.sleep(max(delay, 0.0))
        return json.dumps({"sent": n, "send_sec": time.perf_counter() - start, "cost": cost})

    return handle


async def _serve_stdin(handle: Any, *, announce: bool = True) -> None:
    """Answer one line of stdout per command line on stdin, until stdin closes."""
    loop = asyncio.get_running_loop()
    reader = asyncio.StreamReader()
    await loop.connect_read_pipe(lambda: asyncio.StreamReaderProtocol(reader), sys.stdin)
    if announce:
        print("ready", flush=True)
    while line := (await reader.readline()).decode().strip():
        result = handle(line)
        if asyncio.iscoroutine(result):
            result = await result
        print(result, flush=True)


_ROLES = {
    ("recv", "aiorobot"): _aiorobot_receiver,
    ("send", "aiorobot"): _aiorobot_sender,
    ("recv", "zenoh"): _zenoh_receiver,
    ("send", "zenoh"): _zenoh_sender,
    ("recv", "zenoh-loop"): lambda port: _zenoh_receiver(port, f"{_SERVICE}-loop", hop=True),
    ("send", "zenoh-loop"): lambda port: _zenoh_sender(port, f"{_SERVICE}-loop"),
    ("recv", "iceoryx2"): _iceoryx2_receiver,
    ("send", "iceoryx2"): _iceoryx2_sender,
    ("recv", "dora-rs"): lambda port: _dora_role("receiver", port),
    ("send", "dora-rs"): lambda port: _dora_role("sender", port),
    ("recv", "aiorobot-iox"): lambda port: _aiorobot_receiver(port, iceoryx2=True),
    ("send", "aiorobot-iox"): lambda port: _aiorobot_sender(port, iceoryx2=True),
}


def _dora_role(name: str, daemon_port: int) -> Any:
    from . import _dora

    return getattr(_dora, name)(daemon_port)


# -- the parent -----------------------------------------------------------------------------------


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


class _Peer:
    """A child process answering one stdout line per stdin command."""

    def __init__(self, role: str, path: str, port: int) -> None:
        self.proc = subprocess.Popen(
            [sys.executable, "-m", "aiorobot.bench._zenoh", role, path, str(port)],
            stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True,
        )
        self.role, self.path = role, path

    def ready(self) -> str | None:
        assert self.proc.stdout is not None
        line = self.proc.stdout.readline().strip()
        return None if line == "ready" else f"the {self.path} {self.role} process did not start ({line or 'no output'})"

    def ask(self, command: str) -> dict[str, Any]:
        assert self.proc.stdin is not None and self.proc.stdout is not None
        try:
            self.proc.stdin.write(command + "\n")
            self.proc.stdin.flush()
        except BrokenPipeError:
            raise RuntimeError(f"the {self.path} {self.role} process ended (exit status {self.proc.wait()})") from None
        line = self.proc.stdout.readline()
        if not line:
            raise RuntimeError(f"the {self.path} {self.role} process ended (exit status {self.proc.wait()})")
        return dict(json.loads(line))

    def close(self) -> None:
        if self.proc.stdin is not None:
            with contextlib.suppress(BrokenPipeError):  # a peer that ended leaves a command unflushed
                self.proc.stdin.close()
        try:
            self.proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()
        if self.proc.stdout is not None:
            self.proc.stdout.close()


def open_router(port: int) -> Any:
    """A zenoh router session on ``tcp/127.0.0.1:<port>`` (what ``aiorobot router`` runs; multicast
    scouting off), for the bench's pairs and the transport tests."""
    import zenoh

    cfg = zenoh.Config()
    cfg.insert_json5("mode", '"router"')
    cfg.insert_json5("listen/endpoints", f'["tcp/127.0.0.1:{port}"]')
    cfg.insert_json5("scouting/multicast/enabled", "false")
    return zenoh.open(cfg)


def _stats(values_ns: list[int]) -> dict[str, Any]:
    import numpy as np

    if not values_ns:
        return {"n": 0}
    a = np.asarray(values_ns, dtype=np.float64) / 1000.0
    return {"n": int(a.size), "p50_us": float(np.percentile(a, 50)), "p99_us": float(np.percentile(a, 99))}


def run(quick: bool = False) -> dict[str, Any]:
    """Each available path's small-message and image one-way latency and burst rate, interleaved."""
    from ._noise import NoiseMeter

    rounds, n_small, n_image, n_burst = (1, 200, 10, 2000) if quick else (3, 2000, 100, 20000)
    reasons = available_paths()
    paths = [p for p, why in reasons.items() if why is None]
    port = _free_port()
    router = open_router(port)
    pairs: dict[str, tuple[_Peer, _Peer]] = {}
    pooled: dict[str, dict[str, Any]] = {
        p: {"small": [], "image": [], "burst": [], "small_sent": 0, "image_sent": 0, "small_cost": [], "image_cost": []}
        for p in paths
    }
    errors: dict[str, str] = {}
    ports = dict.fromkeys(paths, port)
    dora = None
    try:
        if "dora-rs" in paths:  # its peers join a dataflow of their own daemon's (the port they are given)
            from ._dora import DoraDataflow

            dora = DoraDataflow()
            try:
                dora.start()
                ports["dora-rs"] = dora.daemon_port
            except RuntimeError as err:
                errors["dora-rs"] = str(err)
                del ports["dora-rs"]
        with NoiseMeter() as meter:
            started = {path: (_Peer("recv", path, p), _Peer("send", path, p)) for path, p in ports.items()}
            for path, (recv, send) in started.items():
                why = recv.ready() or send.ready()
                if why is not None:
                    errors[path] = why
                    recv.close(), send.close()
                    continue
                pairs[path] = (recv, send)
                try:
                    _warm_up(recv, send)
                except (RuntimeError, ValueError) as err:
                    errors[path] = str(err)
                    del pairs[path]
                    send.close(), recv.close()
            for r in range(rounds):
                order = list(pairs)[r % max(len(pairs), 1):] + list(pairs)[: r % max(len(pairs), 1)]
                for path in order:
                    recv, send = pairs[path]
                    try:
                        _round(recv, send, pooled[path], n_small, n_image, n_burst)
                    except (RuntimeError, ValueError) as err:
                        errors[path] = str(err)
        noise = meter.result.as_dict() if meter.result is not None else {}
    finally:
        for recv, send in pairs.values():
            send.close()
            recv.close()
        if dora is not None:
            dora.close()
        router.close()
    rows = {}
    for path in paths:
        if path in errors:
            rows[path] = {"error": errors[path]}
            continue
        got = pooled[path]
        rates = [b["received"] / max((b["last"] - b["first"]) / 1e9, 1e-9) for b in got["burst"] if b["received"] > 1]
        cpu = [b for b in got["burst"] if b.get("cpu_sec") is not None and b["received"]]
        received = sum(b["received"] for b in cpu)
        cpu_us = {k: 1e6 * sum(b["cpu_sec"][k] for b in cpu) / received for k in ("zenoh", "other")} if received else None
        rows[path] = {
            "small": {**_stats(got["small"]), "sent": got["small_sent"], "send_call": _stats(got["small_cost"])},
            "image": {**_stats(got["image"]), "sent": got["image_sent"], "send_call": _stats(got["image_cost"])},
            "burst": {
                "sent": sum(b["sent"] for b in got["burst"]),
                "received": sum(b["received"] for b in got["burst"]),
                "recv_msgs_per_sec": rates,
                # the receiving process's CPU per received message during the bursts (all its
                # threads: zenoh's runtime threads, and the rest), None where /proc cannot tell
                "recv_cpu_us_per_msg": cpu_us,
            },
        }
    skipped = {p: why for p, why in reasons.items() if why is not None}
    return {"paths": rows, "skipped": skipped, "rounds": rounds, "noise": noise}


def _warm_up(recv: _Peer, send: _Peer) -> None:
    """Until a message gets through (routes and shared memory set up), then forget what came."""
    deadline = time.monotonic() + 20
    while time.monotonic() < deadline:
        send.ask("small 20")
        send.ask("image 2")
        if recv.ask("report")["lat"]["small"]:
            _collect(recv, 1 << 30, "small", quiet_sec=0.1, first_sec=0.1)  # what of the warm-up is still on its way
            return
    raise RuntimeError(f"nothing reached the {recv.path} receiver in 20 s")


def _round(recv: _Peer, send: _Peer, into: dict[str, Any], n_small: int, n_image: int, n_burst: int) -> None:
    reply = send.ask(f"small {n_small}")
    sent = reply["sent"]
    into["small_sent"] += sent
    into["small_cost"] += reply["cost"]
    into["small"] += _collect(recv, sent, "small")["small"]
    reply = send.ask(f"image {n_image}")
    sent = reply["sent"]
    into["image_sent"] += sent
    into["image_cost"] += reply["cost"]
    into["image"] += _collect(recv, sent, "image")["image"]
    before = _process_cpu(recv.proc.pid)
    sent = send.ask(f"burst {n_burst}")["sent"]
    burst = _collect(recv, sent, "burst")["burst"]
    after = _process_cpu(recv.proc.pid)
    into["burst"].append({"sent": sent, "received": burst["n"], "first": burst["first"], "last": burst["last"],
                          "cpu_sec": None if before is None or after is None else
                          {k: after.get(k, 0.0) - before.get(k, 0.0) for k in after}})


#: Thread names of zenoh's Rust runtime (its network, receive, transmit, accept and application pools).
_ZENOH_THREADS = ("rx-", "tx-", "net-", "acc-", "app-")


def _process_cpu(pid: int) -> dict[str, float] | None:
    """CPU seconds a process has used so far, ``{"zenoh": ..., "other": ...}``: its zenoh runtime
    threads (by name) and the rest (Python's, pyo3's callback threads among them). None where
    ``/proc`` cannot tell (not Linux). Threads that ended in between are not counted."""
    import glob
    import os

    tick = os.sysconf("SC_CLK_TCK") if hasattr(os, "sysconf") else 100
    out = {"zenoh": 0.0, "other": 0.0}
    tasks = glob.glob(f"/proc/{pid}/task/*")
    if not tasks:
        return None
    for task in tasks:
        try:
            with open(f"{task}/comm") as f:
                name = f.read().strip()
            with open(f"{task}/stat") as f:
                fields = f.read().rsplit(")", 1)[1].split()
        except OSError:  # (the thread ended meanwhile)
            continue
        out["zenoh" if name.startswith(_ZENOH_THREADS) else "other"] += (int(fields[11]) + int(fields[12])) / tick
    return out


def _collect(recv: _Peer, expected: int, kind: str, quiet_sec: float = 0.2, first_sec: float = 5.0) -> dict[str, Any]:
    """The receiver's reports merged until ``expected`` messages of ``kind`` arrived or none came for
    ``quiet_sec`` after the first (what did not arrive by then was lost), or none came at all for
    ``first_sec`` (a loaded machine may take longer than ``quiet_sec`` to deliver the first)."""
    got: dict[str, Any] = {"small": [], "image": [], "burst": {"n": 0, "first": 0, "last": 0}}
    last_change = time.monotonic()
    arrived = False
    while True:
        report = recv.ask("report")
        got["small"] += report["lat"]["small"]
        got["image"] += report["lat"]["image"]
        b, into = report["burst"], got["burst"]
        if b["n"]:
            into["n"] += b["n"]
            into["first"] = into["first"] or b["first"]
            into["last"] = b["last"]
        n = into["n"] if kind == "burst" else len(got[kind])
        if report["lat"]["small"] or report["lat"]["image"] or b["n"]:
            last_change = time.monotonic()
            arrived = True
        if n >= expected or time.monotonic() - last_change > (quiet_sec if arrived else first_sec):
            return got
        time.sleep(0.02)


def table(part: dict[str, Any]) -> Any:
    from ._report import figure_table

    title = "zenoh transport and its peers (two processes each, loopback, interleaved rounds)"
    if "error" in part:
        return figure_table(title, ("path", "note"), [("zenoh", part["error"])])
    nan = float("nan")
    rows: list[tuple[Any, ...]] = []
    names = {
        "aiorobot": "aiorobot Runtime + ZenohTransport",
        "zenoh": "bare zenoh-python put -> callback",
        "zenoh-loop": "bare zenoh-python -> asyncio loop",
        "iceoryx2": "iceoryx2 pub/sub + event",
        "dora-rs": "dora-rs, two Python dynamic nodes",
        "aiorobot-iox": "aiorobot + iceoryx2_topics=[\"*\"]",
    }
    for path, fig in part.get("paths", {}).items():
        if "error" in fig:
            rows.append((names.get(path, path), fig["error"], "", "", "", "", "", "", ""))
            continue
        s, i, b = fig["small"], fig["image"], fig["burst"]
        rates = b["recv_msgs_per_sec"]
        rate = f"{min(rates) / 1000:.1f}-{max(rates) / 1000:.1f}k" if rates else "-"
        if path == "aiorobot-iox":  # its small messages and bursts go over zenoh, as aiorobot's
            rows.append((names[path], "-", "-", i.get("p50_us", nan), i.get("p99_us", nan), "-", "-",
                         "-", i.get("send_call", {}).get("p50_us", nan)))
            continue
        cpu = b.get("recv_cpu_us_per_msg")
        cpu_text = f"{cpu['zenoh'] + cpu['other']:.1f} ({cpu['zenoh']:.1f} in zenoh's threads)" if cpu else "-"
        rows.append((
            names.get(path, path), s.get("p50_us", nan), s.get("p99_us", nan), i.get("p50_us", nan), i.get("p99_us", nan),
            f"{rate} ({100 * b['received'] / max(b['sent'], 1):.0f} % of {b['sent']})", cpu_text,
            s.get("send_call", {}).get("p50_us", nan), i.get("send_call", {}).get("p50_us", nan),
        ))
    for path, why in part.get("skipped", {}).items():
        rows.append((path, f"not measured: {why}", "", "", "", "", "", "", ""))
    return figure_table(
        title,
        ("path", "small p50 us", "small p99 us", "image p50 us", "image p99 us", "burst received msgs/s",
         "receiver CPU us per burst msg", "send call p50 us (small)", "send call p50 us (image)"),
        rows,
        caption=f"small: {SMALL_BYTES} bytes at {SMALL_HZ:.0f} Hz; image: 640x480x3 at {IMAGE_HZ:.0f} Hz; "
        f"pooled over {part.get('rounds', '?')} rounds; receiver CPU: all the receiving process's threads during the bursts; "
        "send call: publish(), put() or send alone, the message built before",
    )


if __name__ == "__main__":
    _role, _path, _port = sys.argv[1], sys.argv[2], int(sys.argv[3])
    if (_role, _path) not in _ROLES:
        print(f"expected ROLE PATH PORT with ROLE recv|send and PATH one of aiorobot, zenoh, zenoh-loop, iceoryx2, aiorobot-iox, dora-rs; found {sys.argv[1:3]}",
              file=sys.stderr)
        sys.exit(2)
    from .. import run as _aiorun

    _aiorun(_ROLES[(_role, _path)](_port))
