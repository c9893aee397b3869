"""Benchmark part ``sim``: lidar ms/scan, camera ms/frame, and the whole simulator's real-time factor.

Figures are medians of repeats on this machine; the baseline row (a 640x480x3 ``numpy`` copy)
is measured in the same run so results can be read as ratios on a noisy host.
"""

from __future__ import annotations

import math
import statistics
import time
from typing import Any

import numpy as np

__all__ = ["run", "table"]


def _median_ms(fn: Any, repeats: int, inner: int) -> float:
    samples = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        for _ in range(inner):
            fn()
        samples.append((time.perf_counter() - t0) / inner * 1e3)
    return statistics.median(samples)


def _lidar_ms(repeats: int, inner: int) -> float:
    from aiorobot.sim import LidarModel, World

    rng = np.random.default_rng(0)
    grid = np.full((400, 400), 0, dtype=np.int8)  # 20 m x 20 m at 5 cm
    grid[:4], grid[-4:], grid[:, :4], grid[:, -4:] = 100, 100, 100, 100
    for _ in range(60):  # boxes
        r, c = rng.integers(10, 380, 2)
        grid[r : r + rng.integers(4, 20), c : c + rng.integers(4, 20)] = 100
    grid[190:210, 190:210] = 0
    world = World("bench", grid, 0.05, (-10.0, -10.0, 0.0))
    lidar = LidarModel()
    lidar.measure(world, 0.0, 0.0, 0.0, rng)  # compile / load the cache
    return _median_ms(lambda: lidar.measure(world, 0.0, 0.0, 0.3, rng), repeats, inner)


def _camera_ms(repeats: int, inner: int) -> tuple[float, int]:
    from aiorobot.sim import CameraModel, Landmark, MarkerRenderer, camera_pose_matrix

    landmarks = [
        Landmark(i, "DICT_4X4_50", 0.2, 3.0 + 0.5 * (i % 2), -1.0 + 0.4 * i, 0.25 + 0.1 * (i % 3 - 1), math.pi)
        for i in range(6)
    ]
    renderer = MarkerRenderer(landmarks, CameraModel())
    pose = camera_pose_matrix(0.0, 0.0, 0.25, 0.0)
    _, drawn = renderer.render(pose)
    return _median_ms(lambda: renderer.render(pose), repeats, inner), len(drawn)


def _whole_sim(sim_sec: float) -> dict[str, float]:
    import aiorobot

    async def main() -> dict[str, float]:
        from aiorobot import Node, Runtime
        from aiorobot.msgs.geometry_msgs import Twist
        from aiorobot.sim import Simulator

        async with Runtime(use_sim_time=True, handle_signals=False) as rt:
            sim = rt.add_node(Simulator(parameter_overrides={
                "world": "warehouse", "real_time_factor": 0.0, "duration_sec": sim_sec}))
            driver = rt.add_node(Node("bench_driver"))
            pub = driver.create_publisher(Twist, "/cmd_vel", 10)

            def tick() -> None:
                msg = Twist()
                msg.linear.x, msg.angular.z = 0.3, 0.2
                pub.publish(msg)

            driver.create_timer(0.05, tick)
            await rt.spin(duration_sec=600.0)
            return {"sim_sec": sim.time_ns / 1e9, "wall_sec": sim.wall_elapsed_sec,
                    "real_time_factor": sim.achieved_real_time_factor, "steps": float(sim.steps)}

    return aiorobot.run(main())


def run(quick: bool = False) -> dict[str, Any]:
    repeats, inner = (5, 20) if quick else (11, 100)
    baseline_image = np.zeros((480, 640, 3), dtype=np.uint8)
    copy_ms = _median_ms(lambda: baseline_image.copy(), repeats, inner)
    lidar_ms = _lidar_ms(repeats, inner)
    camera_ms, markers = _camera_ms(repeats, max(inner // 4, 5))
    whole = _whole_sim(5.0 if quick else 20.0)
    return {
        "baseline_image_copy_ms": copy_ms,
        "lidar_ms_per_scan": lidar_ms,
        "lidar_beams": 360,
        "camera_ms_per_frame": camera_ms,
        "camera_markers": markers,
        "sim_real_time_factor": whole["real_time_factor"],
        "sim_seconds": whole["sim_sec"],
        "sim_wall_seconds": whole["wall_sec"],
    }


def table(part: dict[str, Any]) -> Any:
    from ._report import figure_table

    rows = [
        ("lidar scan (360 beams, 20 m x 20 m at 5 cm)", part["lidar_ms_per_scan"], "<= 0.3 ms"),
        (f"camera frame ({part['camera_markers']} markers, 640x480 rgb8)", part["camera_ms_per_frame"], "<= 3 ms"),
        ("baseline: copy of one 640x480x3 image", part["baseline_image_copy_ms"], ""),
    ]
    table_ = figure_table("sim: ms per sample (median)", ("what", "ms", "target"), rows,
                          caption=(f"whole simulator (warehouse, all sensors at default rates, real_time_factor=0): "
                                   f"{part['sim_real_time_factor']:.1f}x real time "
                                   f"({part['sim_seconds']:.0f} sim s in {part['sim_wall_seconds']:.1f} s); target >= 10x"))
    return table_
