"""Bench part ``perception``: frame transport vs offload's copy path, ArUco throughput, the seed with real perception.

1. Transport: a 640x480x3 Image handed to a pipeline worker through the frame
   ring (main-process cost in the subscription callback, and arrival -> kernel
   start) against ``Node.offload`` of the same Image (its pickling + shared
   memory copy in the main process, and call -> worker start), one frame at a
   time, same run.
2. ArUco on 640x480 with 4 markers: frames/s inline, and through a pipeline with
   1 and 2 workers (frames published back to back, every one processed).
3. The seed experiment with real perception: a 50 Hz control timer on the
   priority loop while an ArUco pipeline (1 worker) takes a 30 fps camera; the
   control periods' p99/max and the pipeline's stamp -> published latency.
"""

from __future__ import annotations

import asyncio
import math
import time
from typing import Any

import numpy as np

__all__ = ["run", "table"]


def _touch(pixels: Any, frame: Any) -> None:
    """A kernel that only reads one pixel (transport cost only)."""
    int(pixels[0, 0, 0])


def _start_time(msg: Any) -> float:
    return time.monotonic()


def _frame_with_markers() -> np.ndarray:
    from aiorobot.perception import pinhole_matrix, render_markers

    facing = np.diag([1.0, -1.0, -1.0])
    spots = [(-0.6, -0.4), (0.6, -0.4), (-0.6, 0.5), (0.6, 0.5)]
    return render_markers([(i, 0.4, facing, np.array([x, y, 2.5])) for i, (x, y) in zip((3, 11, 27, 42), spots)],
                          pinhole_matrix())


def _image(pixels: np.ndarray, node: Any = None) -> Any:
    from aiorobot.msgs.sensor_msgs import Image

    msg = Image(height=pixels.shape[0], width=pixels.shape[1], encoding="rgb8", step=pixels.shape[1] * 3,
                data=np.ascontiguousarray(pixels).ravel())
    msg.header.frame_id = "camera_optical_frame"
    if node is not None:
        msg.header.stamp = node.now().to_msg()
    return msg


def _camera_info() -> Any:
    from aiorobot.msgs.sensor_msgs import CameraInfo
    from aiorobot.perception import pinhole_matrix

    return CameraInfo(width=640, height=480, k=pinhole_matrix().ravel(), d=np.zeros(5))


async def _wait(predicate: Any, timeout_sec: float = 60.0) -> None:
    async with asyncio.timeout(timeout_sec):
        while not predicate():
            await asyncio.sleep(0.0005)


def _pct(values: list[float], q: float) -> float:
    return float(np.percentile(np.asarray(values), q)) if values else math.nan


async def _transport(frames: int) -> dict[str, Any]:
    from aiorobot import Node, Runtime
    from aiorobot._core import _offload
    from aiorobot.msgs.sensor_msgs import Image
    from aiorobot.perception import Pipeline

    pixels = np.random.default_rng(0).integers(0, 255, (480, 640, 3), dtype=np.uint8)
    async with Runtime(handle_signals=False) as rt:
        node = rt.add_node(Node("bench_transport"))
        pub = node.create_publisher(Image, "/bench/image", 10)
        pipeline = Pipeline(node, "/bench/image", Image, _touch, workers=1, queue=1)
        await pipeline.start()
        msg = _image(pixels)
        pub.publish(msg)  # warm-up: the worker's first frame imports the kernel
        await _wait(lambda: pipeline.statistics().processed == 1)
        pipeline.reset_statistics()
        for i in range(1, frames + 1):
            pub.publish(msg)
            await _wait(lambda: pipeline.statistics().processed == i + 1)
        stats = pipeline.statistics().latency
        ring = {"handoff_p50_ms": stats["handoff"].p50_ms, "to_worker_p50_ms": stats["to_worker"].p50_ms,
                "to_worker_p99_ms": stats["to_worker"].p99_ms}
        cost, one_way = [], []
        await node.offload(_start_time, msg)  # warm the pool
        for _ in range(frames):
            t0 = time.perf_counter()
            payload, segments = _offload.dumps((_start_time, (msg,), {}))
            cost.append((time.perf_counter() - t0) * 1e3)
            _offload.release(segments)
            sent = time.monotonic()
            started = await node.offload(_start_time, msg)
            one_way.append((started - sent) * 1e3)
    offload = {"handoff_p50_ms": _pct(cost, 50), "to_worker_p50_ms": _pct(one_way, 50),
               "to_worker_p99_ms": _pct(one_way, 99)}
    return {"frames": frames, "ring": ring, "offload": offload}


async def _aruco_fps(frames: int, pixels: np.ndarray) -> dict[str, Any]:
    from aiorobot import Runtime
    from aiorobot.perception import ArucoNode, detect_markers, pinhole_matrix

    t0 = time.perf_counter()
    for _ in range(frames):
        found = detect_markers(pixels, pinhole_matrix(), None, 0.4)
    inline = frames / (time.perf_counter() - t0)
    result: dict[str, Any] = {"frames": frames, "markers_found": len(found), "inline_fps": inline}
    for workers in (1, 2):
        async with Runtime(handle_signals=False) as rt:
            aruco = ArucoNode(parameter_overrides={"workers": workers, "queue": 1, "policy": "drop_oldest",
                                                   "marker_length": 0.4})
            rt.add_node(aruco)
            from aiorobot import Node
            from aiorobot.msgs.sensor_msgs import CameraInfo, Image

            cam = rt.add_node(Node("bench_camera"))
            info_pub = cam.create_publisher(CameraInfo, "/camera/camera_info", 10)
            image_pub = cam.create_publisher(Image, "/camera/image_raw", frames + 10)
            await aruco.pipeline.start()
            info_pub.publish(_camera_info())
            await _wait(lambda: aruco._camera is not None)
            for _ in range(2 * workers):  # warm-up: imports and the detector in every worker
                image_pub.publish(_image(pixels, cam))
            await _wait(lambda: aruco.pipeline.statistics().received >= 2 * workers
                        and aruco.pipeline.statistics().in_flight == 0)
            stats = aruco.pipeline.statistics
            done, received = stats().processed, stats().received
            t0 = time.perf_counter()
            for sent in range(1, frames + 1):  # keep every worker busy and one frame waiting, drop none
                image_pub.publish(_image(pixels, cam))
                await _wait(lambda: (received + sent - stats().received) + stats().in_flight <= workers)
            await _wait(lambda: stats().processed >= done + frames)
            elapsed = time.perf_counter() - t0
            result[f"workers_{workers}_fps"] = (stats().processed - done) / elapsed
            result[f"workers_{workers}_kernel_p50_ms"] = stats().latency["kernel"].p50_ms
    return result


async def _seed(periods: int, pixels: np.ndarray) -> dict[str, Any]:
    from aiorobot import Node, Runtime
    from aiorobot.bench._stats import period_stats, periods_from_stamps
    from aiorobot.msgs.sensor_msgs import CameraInfo, Image
    from aiorobot.perception import ArucoNode

    warmup = 5
    async with Runtime(handle_signals=False) as rt:
        aruco = ArucoNode(parameter_overrides={"workers": 1, "marker_length": 0.4})
        rt.add_node(aruco)
        await aruco.pipeline.start()
        camera = Node("bench_camera")
        info_pub = camera.create_publisher(CameraInfo, "/camera/camera_info", 10)
        image_pub = camera.create_publisher(Image, "/camera/image_raw", 10)
        camera.create_timer(1 / 30, lambda: (info_pub.publish(_camera_info()), image_pub.publish(_image(pixels, camera))))
        rt.add_node(camera)
        await _wait(lambda: aruco.pipeline.statistics().published >= 3)  # the pipeline is warm
        aruco.pipeline.reset_statistics()

        stamps: list[float] = []
        finished = asyncio.Event()
        loop = asyncio.get_running_loop()

        class Control(Node):
            def __init__(self) -> None:
                super().__init__("control")
                self.create_timer(0.02, self.tick)

            def tick(self) -> None:
                stamps.append(time.perf_counter())
                if len(stamps) == periods + warmup + 1:
                    loop.call_soon_threadsafe(finished.set)

        before = aruco.pipeline.statistics().published
        rt.add_node(Control(), executor="priority")
        await finished.wait()
        stats = aruco.pipeline.statistics()
        taken = stamps[:periods + warmup + 1]  # not the ticks that come while the runtime closes
        elapsed = taken[-1] - taken[0]
    control = period_stats(periods_from_stamps(taken, warmup), 20.0)
    latency = stats.latency.get("stamp_to_publish")
    return {
        "periods": control.samples,
        "control_p50_ms": control.p50_ms,
        "control_p99_ms": control.p99_ms,
        "control_max_ms": control.max_ms,
        "aruco_fps": (stats.published - before) / elapsed if elapsed else math.nan,
        "added_latency_p50_ms": latency.p50_ms if latency else math.nan,
        "added_latency_p99_ms": latency.p99_ms if latency else math.nan,
        "dropped_queue": stats.dropped_queue,
    }


async def _main(quick: bool) -> dict[str, Any]:
    pixels = _frame_with_markers()
    return {
        "transport": await _transport(30 if quick else 300),
        "aruco": await _aruco_fps(10 if quick else 120, pixels),
        "seed": await _seed(25 if quick else 250, pixels),
    }


def run(quick: bool = False) -> dict[str, Any]:
    """Measure the perception rows; returns JSON-able figures (milliseconds, frames per second)."""
    import aiorobot

    return aiorobot.run(_main(quick))


def table(part: dict[str, Any]) -> Any:
    """The part's rows as a rich table."""
    from aiorobot.bench._report import figure_table

    t, a, s = part["transport"], part["aruco"], part["seed"]
    rows = [
        ("frame ring: main-process cost per 640x480x3 frame, p50 ms", t["ring"]["handoff_p50_ms"]),
        ("offload copy path: main-process cost per frame, p50 ms", t["offload"]["handoff_p50_ms"]),
        ("frame ring: image -> worker one-way, p50 ms", t["ring"]["to_worker_p50_ms"]),
        ("offload copy path: call -> worker one-way, p50 ms", t["offload"]["to_worker_p50_ms"]),
        ("ArUco 640x480, 4 markers: inline fps", a["inline_fps"]),
        ("ArUco: pipeline 1 worker fps", a["workers_1_fps"]),
        ("ArUco: pipeline 2 workers fps", a["workers_2_fps"]),
        ("seed, 30 fps ArUco: added latency stamp -> published p50 ms", s["added_latency_p50_ms"]),
        ("seed, 30 fps ArUco: added latency p99 ms", s["added_latency_p99_ms"]),
        ("seed: 50 Hz control on the priority loop, period p99 ms", s["control_p99_ms"]),
        ("seed: control period max ms", s["control_max_ms"]),
        ("seed: ArUco frames published per second", s["aruco_fps"]),
    ]
    return figure_table("perception", ("figure", "value"), rows,
                        caption=f"{t['frames']} transport frames, {a['frames']} ArUco frames, "
                                f"{s['periods']} control periods (nominal 20 ms)")
