"""Part ``latency``: publish -> callback latency and throughput.

Paths measured, each with a Twist (52 bytes of CDR) and a 640x480x3 uint8 Image:

- ``same loop``: publisher and subscriber nodes both on the main loop;
- ``main -> priority``: the subscriber node on the priority loop;
- ``process pool``: ``await node.offload(echo, msg)``, the round trip through
  the runtime's process pool (the message goes there and back);
- ``zenoh``: a pointer row; two-process figures are the ``zenoh`` part's (:mod:`aiorobot.bench._zenoh`).

Latency: one message at a time, from just before ``publish`` to the start of the
subscriber's callback (one clock, ``time.perf_counter``, read in both threads).
Throughput: bursts of messages published back to back; messages per second
delivered to the callback (none dropped: the queue holds a whole burst).
"""

from __future__ import annotations

import asyncio
import os
import time
from typing import Any

from ._noise import NoiseMeter
from ._stats import latency_stats

__all__ = ["ZENOH_NOTE", "echo", "run"]

ZENOH_NOTE = "two processes: see the zenoh transport table"
_BURST = 500


def echo(msg: Any) -> Any:
    """Return the message: the process-pool round trip's work."""
    return msg


def _payloads() -> dict[str, Any]:
    import numpy as np

    from aiorobot.msgs.geometry_msgs import Twist, Vector3
    from aiorobot.msgs.sensor_msgs import Image

    image_data = np.random.default_rng(0).integers(0, 256, size=640 * 480 * 3, dtype=np.uint8)
    return {
        "Twist": lambda i: Twist(linear=Vector3(x=float(i))),
        "Image 640x480x3": lambda i: Image(height=480, width=640, encoding="rgb8", step=640 * 3, data=image_data),
    }


async def _pubsub(executor: str, make: Any, n_latency: int, throughput_sec: float) -> dict[str, Any]:
    from aiorobot import Node, QoSProfile, Runtime

    main_loop = asyncio.get_running_loop()
    arrived = asyncio.Event()
    received: list[float] = []

    class Sink(Node):
        def __init__(self) -> None:
            super().__init__("sink")
            self.count = 0
            self.target = -1
            self.create_subscription(type(make(0)), "/bench", self.on_msg, QoSProfile(depth=_BURST))

        def on_msg(self, msg: Any) -> None:
            received.append(time.perf_counter())
            self.count += 1
            if self.count == self.target or self.target == 0:
                if executor == "main":
                    arrived.set()
                else:
                    main_loop.call_soon_threadsafe(arrived.set)

    async with Runtime(handle_signals=False) as rt:
        source = Node("source")
        pub = source.create_publisher(type(make(0)), "/bench", QoSProfile(depth=_BURST))
        sink = Sink()
        rt.add_node(source)
        rt.add_node(sink, executor=executor)
        await asyncio.sleep(0.05)  # let both nodes start their dispatchers
        msgs = [make(i) for i in range(_BURST)]

        # latency: one message in flight at a time
        sink.target = 0
        sent: list[float] = []
        for i in range(n_latency):
            arrived.clear()
            msg = msgs[i % _BURST]
            sent.append(time.perf_counter())
            pub.publish(msg)
            await arrived.wait()
        latencies = [(r - s) * 1e6 for s, r in zip(sent, received)]

        # throughput: bursts of _BURST messages back to back
        delivered = 0
        t0 = time.perf_counter()
        while time.perf_counter() - t0 < throughput_sec:
            arrived.clear()
            sink.count = 0
            sink.target = _BURST
            for msg in msgs:
                pub.publish(msg)
            await arrived.wait()
            delivered += _BURST
        elapsed = time.perf_counter() - t0
    return {"latency": latency_stats(latencies).as_dict(), "msgs_per_sec": delivered / elapsed}


async def _pool(make: Any, n_latency: int, throughput_sec: float) -> dict[str, Any]:
    from aiorobot import Node, Runtime

    async with Runtime(handle_signals=False) as rt:
        node = Node("offloader")
        rt.add_node(node)
        msg = make(0)
        workers = os.cpu_count() or 2  # the runtime's default pool size
        await asyncio.gather(*[node.offload(echo, msg) for _ in range(2 * workers)])  # start the workers
        latencies = []
        for _ in range(n_latency):
            t0 = time.perf_counter()
            await node.offload(echo, msg)
            latencies.append((time.perf_counter() - t0) * 1e6)
        done = 0
        t0 = time.perf_counter()
        while time.perf_counter() - t0 < throughput_sec:
            await asyncio.gather(*[node.offload(echo, msg) for _ in range(2 * workers)])
            done += 2 * workers
        elapsed = time.perf_counter() - t0
    return {"latency": latency_stats(latencies).as_dict(), "msgs_per_sec": done / elapsed}


async def _main(quick: bool) -> list[dict[str, Any]]:
    rows: list[dict[str, Any]] = []
    for payload, make in _payloads().items():
        small = payload == "Twist"
        n = (200 if quick else 3000) if small else (20 if quick else 300)
        n_pool = (20 if quick else 300) if small else (5 if quick else 60)
        tput_sec = 0.05 if quick else 1.0
        for path, executor in (("same loop", "main"), ("main -> priority", "priority")):
            with NoiseMeter() as meter:
                figures = await _pubsub(executor, make, n, tput_sec)
            rows.append({"path": path, "payload": payload, **figures, "noise": meter.result.as_dict()})  # type: ignore[union-attr]
        with NoiseMeter() as meter:
            figures = await _pool(make, n_pool, tput_sec)
        rows.append({"path": "process pool round trip", "payload": payload, **figures, "noise": meter.result.as_dict()})  # type: ignore[union-attr]
        rows.append({"path": "zenoh", "payload": payload, "note": ZENOH_NOTE})
    return rows


def run(quick: bool = False) -> dict[str, Any]:
    """Measure every path and payload; returns ``{"rows": [...], "noise": {...}}``."""
    import aiorobot

    with NoiseMeter() as meter:
        rows = aiorobot.run(_main(quick))
    assert meter.result is not None
    return {"rows": rows, "noise": meter.result.as_dict()}
