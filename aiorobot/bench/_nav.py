"""Part ``nav``: the navigation cores' costs (Numba kernels warmed up first).

- A* on a 400x400 inflated costmap (a seeded maze of walls), corner to corner;
- an AMCL update with 500 particles x 60 beams (sensor model + resampling);
- a costmap update from one 360-beam scan (obstacle layer + inflation) on a 400x400 map;
- one Regulated Pure Pursuit step;
- one MPPI control cycle with Nav2's defaults (batch_size 1000, time_steps 56, eight critics) on
  that costmap, the robot driven along the serpentine's plan by the commands.
"""

from __future__ import annotations

import math
import time
from typing import Any

import numpy as np

from ._report import figure_table
from ._stats import latency_stats

__all__ = ["run", "table"]


def _timed(fn: Any, n: int) -> dict[str, Any]:
    fn()  # warm-up (compiles on the first call in a fresh process)
    samples = []
    for _ in range(n):
        t0 = time.perf_counter()
        fn()
        samples.append((time.perf_counter() - t0) * 1e6)
    return latency_stats(samples).as_dict()


def _grid() -> np.ndarray:
    """A serpentine: walls every 50 cells with a 40-cell gap alternating top and bottom (a long path)."""
    static = np.zeros((400, 400), np.uint8)
    static[0, :] = static[-1, :] = static[:, 0] = static[:, -1] = 254
    for i, c in enumerate(range(50, 400, 50)):
        if i % 2 == 0:
            static[:350, c] = 254
        else:
            static[50:, c] = 254
    return static


def run(quick: bool = False) -> dict[str, Any]:
    from aiorobot.nav import Amcl, AmclParameters, Costmap, Mppi, MppiParameters, RegulatedPurePursuit, plan

    n = 5 if quick else 30
    static = _grid()
    cm = Costmap(static, 0.05, (0.0, 0.0))
    out: dict[str, Any] = {}
    out["astar_400x400_us"] = _timed(lambda: plan(cm, (0.5, 0.5), (19.5, 19.5), smooth=False), n)
    out["plan_with_smoothing_us"] = _timed(lambda: plan(cm, (0.5, 0.5), (19.5, 19.5)), max(3, n // 3))
    occ = static == 254
    amcl = Amcl(occ, 0.05, (0.0, 0.0), AmclParameters(min_particles=500, max_particles=500, max_beams=60), seed=0)
    amcl.set_initial_pose(10.0, 10.0, 0.0)
    ranges = np.random.default_rng(1).uniform(0.5, 8.0, 360)
    odom = [0.0, 0.0, 0.0]

    def amcl_step() -> None:
        odom[0] += 0.3
        amcl.update(tuple(odom), ranges, -math.pi, 2 * math.pi / 360, range_max=12.0)

    amcl.update(tuple(odom), ranges, -math.pi, 2 * math.pi / 360, range_max=12.0)
    out["amcl_500x60_us"] = _timed(amcl_step, n)
    angles = np.linspace(-math.pi, math.pi, 360, endpoint=False)
    pts = np.column_stack([10 + 3 * np.cos(angles), 10 + 3 * np.sin(angles)])
    hits = np.ones(360, dtype=bool)

    def costmap_step() -> None:
        cm.clear_obstacles()
        cm.mark_scan((10.0, 10.0), pts, hits)
        cm.update()

    out["costmap_scan_update_us"] = _timed(costmap_step, n)
    rpp = RegulatedPurePursuit(costmap=cm)
    path = plan(cm, (0.5, 0.5), (19.5, 19.5)).poses
    rpp.set_plan(path)
    out["rpp_step_us"] = _timed(lambda: rpp.step((float(path[0, 0]), float(path[0, 1]), float(path[0, 2])), 0.3), n * 10)
    mppi = Mppi(MppiParameters(batch_size=1000, time_steps=56), cm)
    mppi.set_plan(path)
    pose = [float(path[0, 0]), float(path[0, 1]), float(path[0, 2])]

    def mppi_cycle() -> None:
        c = mppi.step((pose[0], pose[1], pose[2]), mppi.last_command[0])
        dt = mppi.p.controller_period
        pose[0] += c.linear * math.cos(pose[2]) * dt
        pose[1] += c.linear * math.sin(pose[2]) * dt
        pose[2] += c.angular * dt

    out["mppi_cycle_us"] = _timed(mppi_cycle, n * 10)
    return out


def table(part: dict[str, Any]) -> Any:
    rows = [
        ("A* 400x400 costmap, corner to corner (target <= 20 ms)", part["astar_400x400_us"]),
        ("plan incl. line-of-sight smoothing", part["plan_with_smoothing_us"]),
        ("AMCL update, 500 particles x 60 beams (target <= 5 ms)", part["amcl_500x60_us"]),
        ("costmap update from one 360-beam scan (target <= 2 ms)", part["costmap_scan_update_us"]),
        ("Regulated Pure Pursuit step", part["rpp_step_us"]),
        ("MPPI control cycle, 1000 x 56 (target <= 20 ms p99)", part["mppi_cycle_us"]),
    ]
    return figure_table("navigation cores (ms)", ("figure", "p50", "p99", "max"),
                        [(name, s["p50_us"] / 1e3, s["p99_us"] / 1e3, s["max_us"] / 1e3) for name, s in rows])
