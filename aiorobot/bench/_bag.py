"""Part ``bag``: recording, playback spacing and the Foxglove bridge's effect on control.

- ``record``: 1 kHz Twists + 30 fps 640x480x3 images published on the main loop for a few
  seconds, with and without a :class:`~aiorobot.bag.Recorder`; the recorder's CPU beyond
  serialisation = (CPU with recorder - CPU without) - the time serialising those messages
  takes alone; and how many messages the bag holds against how many were published.
- ``play``: a 1 kHz recording played at rate 1: the error of each arrival spacing against the
  recorded spacing (one tap, one clock).
- ``foxglove``: a 50 Hz timer on the priority loop while the bridge sends a 30 fps image
  topic to a subscribed WebSocket client, beside the same timer with no bridge.
"""

from __future__ import annotations

import asyncio
import json
import tempfile
import time
from pathlib import Path
from typing import Any

from ._noise import NoiseMeter
from ._report import figure_table
from ._stats import latency_stats, period_stats

__all__ = ["run", "table"]


def _image() -> Any:
    import numpy as np

    from aiorobot.msgs.sensor_msgs import Image

    data = np.random.default_rng(0).integers(0, 256, size=640 * 480 * 3, dtype=np.uint8)
    return Image(height=480, width=640, encoding="rgb8", step=1920, data=data)


async def _record_case(duration: float, bag: Path | None) -> dict[str, Any]:
    from aiorobot import Node, Runtime
    from aiorobot.bag import Recorder
    from aiorobot.msgs.geometry_msgs import Twist

    image = _image()
    counts = {"twist": 0, "image": 0}

    class Source(Node):
        def __init__(self) -> None:
            super().__init__("source")
            self.twist = self.create_publisher(Twist, "/cmd_vel", 10)
            self.cam = self.create_publisher(type(image), "/camera/image_raw", 10)
            self.create_timer(0.001, self.fast)
            self.create_timer(1 / 30, self.frame)

        def fast(self) -> None:
            self.twist.publish(Twist())
            counts["twist"] += 1

        def frame(self) -> None:
            self.cam.publish(image)
            counts["image"] += 1

    recorder = None
    async with Runtime(handle_signals=False) as rt:
        if bag is not None:
            recorder = Recorder(path=str(bag), topics=["/cmd_vel", "/camera/image_raw"])
            rt.add_node(recorder)
        rt.add_node(Source())
        await asyncio.sleep(0.2)
        base = dict(counts)
        cpu0, wall0 = time.process_time(), time.perf_counter()
        await rt.spin(duration_sec=duration)
        cpu1, wall1 = time.process_time(), time.perf_counter()
        published = {k: counts[k] - base[k] for k in counts}
        for node in rt.nodes:  # stop publishing before shutdown, so every message had its chance
            for timer in node.timers:
                timer.cancel()
        await asyncio.sleep(0.05)
    out: dict[str, Any] = {"core_pct": 100.0 * (cpu1 - cpu0) / (wall1 - wall0), "published": published, "wall_sec": wall1 - wall0}
    if recorder is not None:
        out["recorded"] = recorder.statistics().messages
        out["published_total"] = sum(counts.values())
    return out


def _serialise_cost(duration: float, published: dict[str, int]) -> float:
    """Share of a core that serialising this many messages takes by itself."""
    from aiorobot.msgs import serialize
    from aiorobot.msgs.geometry_msgs import Twist

    image, twist = _image(), Twist()
    t0 = time.process_time()
    for _ in range(published["twist"]):
        serialize(twist)
    for _ in range(published["image"]):
        serialize(image)
    return 100.0 * (time.process_time() - t0) / duration


async def _play_spacing(quick: bool, tmp: Path) -> dict[str, Any]:
    from aiorobot import QoSProfile, Runtime
    from aiorobot.lowlevel import Tap, add_tap
    from aiorobot.bag import BagWriter, Player
    from aiorobot.msgs import serialize
    from aiorobot.msgs.std_msgs import UInt32

    n = 300 if quick else 2000
    bag = tmp / "spacing"
    with BagWriter(bag) as w:
        w.add_topic("/seq", "std_msgs/msg/UInt32")
        for i in range(n):
            w.write("/seq", 10**9 + i * 1_000_000, serialize(UInt32(data=i)))
    arrivals: list[float] = []
    async with Runtime(handle_signals=False) as rt:
        player = Player(path=str(bag))
        add_tap(rt, Tap(UInt32, "/seq", QoSProfile(), lambda m: arrivals.append(time.perf_counter())))
        rt.add_node(player)
        await player.wait_for_completion(60)
    errors = [abs((b - a) * 1e3 - 1.0) * 1e3 for a, b in zip(arrivals, arrivals[1:])]  # us off 1 ms spacing
    stats = latency_stats(errors).as_dict()
    # Cumulative drift: the last message's time from the first against the recorded span.
    drift_ms = ((arrivals[-1] - arrivals[0]) * 1e3 - (len(arrivals) - 1)) if len(arrivals) > 1 else 0.0
    return {"messages": len(arrivals), "spacing_error_us": stats, "drift_ms": drift_ms}


async def _foxglove_case(with_bridge: bool, duration: float, *, observed: bool = False) -> dict[str, Any]:
    """``observed``: also a node logging 100 lines/s on /rosout with a subscriber, and the control
    node's ``~/get_statistics`` read once a second (what ``aiorobot log`` and ``aiorobot top`` cost)."""
    from aiorobot import Node, Runtime
    from aiorobot.foxglove import FoxgloveBridge

    image = _image()
    stamps: list[float] = []

    class Control(Node):
        def __init__(self) -> None:
            super().__init__("control")
            self.create_timer(0.02, self.tick)

        def tick(self) -> None:
            stamps.append(time.perf_counter())

    class Camera(Node):
        def __init__(self) -> None:
            super().__init__("camera")
            self.pub = self.create_publisher(type(image), "/camera/image_raw", 5)
            self.create_timer(1 / 30, lambda: self.pub.publish(image))

    received = 0
    async with Runtime(handle_signals=False) as rt:
        rt.add_node(Control(), executor="priority")
        rt.add_node(Camera())
        if observed:
            from ._culprit import _observe

            _observe(rt)
        client = None
        if with_bridge:
            import websockets

            bridge = FoxgloveBridge(port=0, max_large_hz=30.0, queue=8)
            rt.add_node(bridge)
            client = await websockets.connect(f"ws://127.0.0.1:{bridge.bound_port}", subprotocols=["foxglove.sdk.v1"], max_size=None)
            async with asyncio.timeout(10):
                while True:
                    doc = await client.recv()
                    if isinstance(doc, str) and json.loads(doc).get("op") == "advertise":
                        chans = [c for c in json.loads(doc)["channels"] if c["topic"] == "/camera/image_raw"]
                        if chans:
                            await client.send(json.dumps({"op": "subscribe", "subscriptions": [{"id": 1, "channelId": chans[0]["id"]}]}))
                            break

            async def drain() -> None:
                nonlocal received
                async for frame in client:
                    if isinstance(frame, bytes):
                        received += 1

            drainer = asyncio.ensure_future(drain())
        await asyncio.sleep(0.3)
        stamps.clear()
        await rt.spin(duration_sec=duration)
        if client is not None:
            await client.close()
            drainer.cancel()
    periods = [(b - a) * 1e3 for a, b in zip(stamps, stamps[1:])]
    return {"stats": period_stats(periods, 20.0).as_dict(), "frames_to_client": received}


def run(quick: bool = False) -> dict[str, Any]:
    duration = 2.0 if quick else 10.0
    out: dict[str, Any] = {"duration_sec": duration}
    with tempfile.TemporaryDirectory(prefix="aiorobot-bench-bag-") as tmp_name:
        tmp = Path(tmp_name)
        with NoiseMeter() as meter:
            base = asyncio.run(_record_case(duration, None))
            rec = asyncio.run(_record_case(duration, tmp / "rec"))
            ser = _serialise_cost(rec["wall_sec"], rec["published"])
        out["record"] = {
            "without_recorder_core_pct": base["core_pct"],
            "with_recorder_core_pct": rec["core_pct"],
            "serialise_core_pct": ser,
            "recorder_beyond_serialise_core_pct": rec["core_pct"] - base["core_pct"] - ser,
            "published": rec["published_total"],
            "recorded": rec["recorded"],
            "noise": _noise(meter),
        }
        with NoiseMeter() as meter:
            play = asyncio.run(_play_spacing(quick, tmp))
        out["play"] = {**play, "noise": _noise(meter)}
    with NoiseMeter() as meter:
        without = asyncio.run(_foxglove_case(False, duration))
        with_bridge = asyncio.run(_foxglove_case(True, duration))
        observed = asyncio.run(_foxglove_case(True, duration, observed=True))
    out["foxglove"] = {"without": without, "with": with_bridge, "observed": observed, "noise": _noise(meter)}
    return out


def _noise(meter: NoiseMeter) -> dict[str, Any] | None:
    from dataclasses import asdict

    return asdict(meter.result) if meter.result is not None else None


def table(part: dict[str, Any]) -> Any:
    rec, play, fox = part["record"], part["play"], part["foxglove"]
    rows: list[tuple[Any, ...]] = [
        ("record 1 kHz Twist + 30 fps image: messages recorded / published", f"{rec['recorded']:,} / {rec['published']:,}"),
        ("  process CPU without recorder (% of a core)", rec["without_recorder_core_pct"]),
        ("  process CPU with recorder", rec["with_recorder_core_pct"]),
        ("  serialising those messages alone", rec["serialise_core_pct"]),
        ("  recorder beyond serialisation (target <= 5)", rec["recorder_beyond_serialise_core_pct"]),
        ("play 1 kHz at rate 1: spacing error p50 (us)", play["spacing_error_us"]["p50_us"]),
        ("  spacing error p99 (us; target <= 1000)", play["spacing_error_us"]["p99_us"]),
        ("  drift over the whole bag (ms)", play["drift_ms"]),
        ("priority 50 Hz timer p99 (ms), no bridge", fox["without"]["stats"]["p99_ms"]),
        ("  with Foxglove client on 30 fps images (target: within 1 ms of 20)", fox["with"]["stats"]["p99_ms"]),
        ("  with bridge + /rosout 100 lines/s + statistics read 1/s (as aiorobot top)", fox["observed"]["stats"]["p99_ms"]),
        ("  max without / with bridge / observed (ms)",
         f"{fox['without']['stats']['max_ms']:.2f} / {fox['with']['stats']['max_ms']:.2f} / {fox['observed']['stats']['max_ms']:.2f}"),
        ("  frames the client received", fox["with"]["frames_to_client"]),
    ]
    return figure_table(f"bags and Foxglove ({part['duration_sec']:g} s per case)", ("figure", "value"), rows)
