"""``aiorobot bench latency`` zenoh rows: two processes on loopback, one-way latency and throughput.

A child process subscribes; the parent publishes messages stamped with
``time.monotonic_ns()`` (one clock for every process on a Linux host), and the
child reports one-way latency (receive minus stamp) and the receive rate of a burst.
"""

from __future__ import annotations

import asyncio
import json
import socket
import subprocess
import sys
import time
from typing import Any

__all__ = ["run", "table"]

_CHILD = r"""
import asyncio, json, sys, time
import aiorobot
from aiorobot import Node, Runtime, QoSProfile, HistoryPolicy
from aiorobot.transport import ZenohTransport
from aiorobot.msgs.geometry_msgs import Twist
from aiorobot.msgs.sensor_msgs import Image

async def main(port, shm):
    lat = {"twist": [], "image": [], "raw": []}
    burst = {"n": 0, "first": 0, "last": 0}
    async with Runtime(transport=ZenohTransport(connect=[f"tcp/127.0.0.1:{port}"], shared_memory=shm), handle_signals=False) as rt:
        node = rt.add_node(Node("bench_sink"))
        def on_twist(m):
            now = time.monotonic_ns()
            if m.linear.y == 1.0:
                burst["n"] += 1
                burst["first"] = burst["first"] or now
                burst["last"] = now
            else:
                lat["twist"].append(now - int(m.linear.x))
        def on_image(m):
            lat["image"].append(time.monotonic_ns() - (m.header.stamp.sec * 1_000_000_000 + m.header.stamp.nanosec))
        keep_all = QoSProfile(history=HistoryPolicy.KEEP_ALL)
        node.create_subscription(Twist, "/bench/twist", on_twist, keep_all)
        node.create_subscription(Image, "/bench/image", on_image, keep_all)
        raw = rt.transport._session.declare_subscriber(
            "bench/raw", lambda s: lat["raw"].append(time.monotonic_ns() - int.from_bytes(s.payload.to_bytes()[:8], "little")))
        print("ready", flush=True)
        loop = asyncio.get_running_loop()
        reader = asyncio.StreamReader()
        await loop.connect_read_pipe(lambda: asyncio.StreamReaderProtocol(reader), sys.stdin)
        while line := (await reader.readline()).decode().strip():
            if line == "report":
                print(json.dumps({"lat": lat, "burst": burst, "received_shm": rt.transport.statistics().received_shm}), flush=True)
                lat = {"twist": [], "image": [], "raw": []}
                burst.update(n=0, first=0, last=0)

aiorobot.run(main(int(sys.argv[1]), sys.argv[2] == "shm"))
"""


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def _stats(values_ns: list[int]) -> dict[str, Any]:
    import numpy as np

    if not values_ns:
        return {"n": 0}
    a = np.asarray(values_ns, dtype=np.float64) / 1000.0
    return {"n": int(a.size), "p50_us": float(np.percentile(a, 50)), "p99_us": float(np.percentile(a, 99))}


def run(quick: bool = False) -> dict[str, Any]:
    """Twist one-way p50/p99 and msgs/s, and a 640x480x3 Image one-way, across two processes.

    Two passes, each with its own subscriber process: shared memory on (Twist, the bare
    zenoh baseline, the burst, the Image through shared memory), then off in both processes
    (the Image through the network stack, what a peer on another host gets).
    """
    from ._noise import NoiseMeter

    with NoiseMeter() as meter:
        figures = _pass(quick, shm=True)
        if "error" not in figures:
            copy = _pass(quick, shm=False)
            figures["image_copy"] = copy.get("image", {"n": 0, "error": copy.get("error")})
        figures["image_shm"] = figures.pop("image", {"n": 0})
    return {**figures, "noise": meter.result.as_dict()}


def _pass(quick: bool, *, shm: bool) -> dict[str, Any]:
    import zenoh

    from .. import run as aiorun

    port = _free_port()
    cfg = zenoh.Config()
    cfg.insert_json5("mode", '"router"')
    cfg.insert_json5("listen/endpoints", f'["tcp/127.0.0.1:{port}"]')
    cfg.insert_json5("scouting/multicast/enabled", "false")
    router = zenoh.open(cfg)
    child = subprocess.Popen(
        [sys.executable, "-c", _CHILD, str(port), "shm" if shm else "copy"],
        stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True,
    )
    try:
        assert child.stdout is not None and child.stdin is not None
        if child.stdout.readline().strip() != "ready":
            return {"error": "the subscriber process did not start"}
        return aiorun(_measure(port, child, quick, shm=shm))
    finally:
        child.kill()
        child.wait()
        router.close()


async def _measure(port: int, child: subprocess.Popen[str], quick: bool, *, shm: bool) -> dict[str, Any]:
    from .. import HistoryPolicy, Node, QoSProfile, Runtime
    from ..msgs.geometry_msgs import Twist, Vector3
    from ..msgs.sensor_msgs import Image
    from ..transport import ZenohTransport

    n_lat, n_burst, n_img = (300, 5000, 30) if quick else (2000, 50000, 200)
    keep_all = QoSProfile(history=HistoryPolicy.KEEP_ALL)
    transport = ZenohTransport(connect=[f"tcp/127.0.0.1:{port}"], shared_memory=shm)
    async with Runtime(transport=transport, handle_signals=False) as rt:
        node = rt.add_node(Node("bench_source"))
        twist = node.create_publisher(Twist, "/bench/twist", keep_all)
        image = node.create_publisher(Image, "/bench/image", keep_all)
        deadline = time.monotonic() + 10
        while (twist.get_subscription_count() == 0 or image.get_subscription_count() == 0) and time.monotonic() < deadline:
            await asyncio.sleep(0.01)
        for _ in range(50):  # warm-up
            twist.publish(Twist(linear=Vector3(x=float(time.monotonic_ns()))))
            await asyncio.sleep(0.001)
        first = await _report(child)
        await _send_images(image, n_img)
        report = await _report(child)
        images = {**_stats(report["lat"]["image"]), "sent_shm": transport.statistics().sent_shm,
                  "received_shm": report["received_shm"] - first["received_shm"]}
        if not shm:
            return {"image": images}
        raw = transport._session.declare_publisher("bench/raw")
        for _ in range(n_lat):
            twist.publish(Twist(linear=Vector3(x=float(time.monotonic_ns()))))
            await asyncio.sleep(0.0005)
            raw.put(time.monotonic_ns().to_bytes(8, "little") + bytes(44))  # same size as a Twist's CDR
            await asyncio.sleep(0.0005)
        await asyncio.sleep(0.5)
        lat = (await _report(child))["lat"]
        start = time.perf_counter()
        for _ in range(n_burst):
            twist.publish(Twist(linear=Vector3(y=1.0)))
        send_sec = time.perf_counter() - start
        await asyncio.sleep(1.0)
        burst = (await _report(child))["burst"]
    recv_sec = max((burst["last"] - burst["first"]) / 1e9, 1e-9)
    return {
        "twist": _stats(lat["twist"]),
        "raw_zenoh": _stats(lat["raw"]),
        "image": images,
        "burst": {"sent": n_burst, "received": burst["n"], "send_msgs_per_sec": n_burst / send_sec,
                  "recv_msgs_per_sec": burst["n"] / recv_sec},
    }


async def _send_images(image: Any, n: int) -> None:
    import numpy as np

    from ..msgs.sensor_msgs import Image

    data = np.zeros(640 * 480 * 3, dtype=np.uint8)
    for _ in range(n):
        now = time.monotonic_ns()
        msg = Image(height=480, width=640, encoding="rgb8", step=640 * 3, data=data)
        msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(now, 1_000_000_000)
        image.publish(msg)
        await asyncio.sleep(0.01)
    await asyncio.sleep(0.3)


async def _report(child: subprocess.Popen[str]) -> dict[str, Any]:
    assert child.stdin is not None and child.stdout is not None
    child.stdin.write("report\n")
    child.stdin.flush()
    line = await asyncio.to_thread(child.stdout.readline)
    return json.loads(line)


def table(part: dict[str, Any]) -> Any:
    from ._report import figure_table

    if "error" in part:
        return figure_table("zenoh transport (two processes, loopback)", ("path", "note"), [("zenoh", part["error"])])
    t, img, b = part["twist"], part["image_copy"], part["burst"]
    shm = part.get("image_shm", {})
    raw = part.get("raw_zenoh", {})
    rows = [
        ("bare zenoh-python put -> callback (baseline)", raw.get("p50_us", float("nan")), raw.get("p99_us", float("nan")), float("nan")),
        ("Twist one-way", t.get("p50_us", float("nan")), t.get("p99_us", float("nan")), float(b["recv_msgs_per_sec"])),
        ("Image 640x480x3 one-way (copy)", img.get("p50_us", float("nan")), img.get("p99_us", float("nan")), float("nan")),
        ("Image 640x480x3 one-way (shared memory)", shm.get("p50_us", float("nan")), shm.get("p99_us", float("nan")), float("nan")),
    ]
    return figure_table(
        "zenoh transport (two processes, loopback)",
        ("path", "p50 us", "p99 us", "msgs/s"),
        rows,
        caption=(
            f"burst: {b['received']}/{b['sent']} received; shared-memory Images: {shm.get('sent_shm', 0)} put, "
            f"{shm.get('received_shm', 0)} received in shared memory"
        ),
    )
