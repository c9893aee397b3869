"""Part ``nav``: the navigation cores' costs (Numba kernels warmed up first).

- A* on a 400x400 inflated costmap (a seeded maze of walls), corner to corner;
- an AMCL update with 500 particles x 60 beams (sensor model + resampling);
- a costmap update from one 360-beam scan (obstacle layer + inflation) on a 400x400 map;
- one Regulated Pure Pursuit step;
- one collision monitor check of a command against a 360-beam scan (stop, slowdown and approach zones).
- SLAM (issue 30's targets): a scan match of 360 beams at 0.05 m against ten scans of the warehouse
  (and at the default 0.025 m), the loop-closure optimisation of a 500-node graph, and a whole
  mapping run of the warehouse loop (simulated lidar included) as a real-time factor.
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
    out["collision_monitor_scan_us"] = _timed(_collision_monitor_step(), n * 10)
    out.update(_slam(quick))
    return out


def _slam(quick: bool) -> dict[str, Any]:
    from aiorobot.demo._slam_figures import WAREHOUSE_LOOP, WAREHOUSE_START, scripted_mapping_run
    from aiorobot.nav._slam_graph import PoseGraph, compose, relative
    from aiorobot.nav._slam_matcher import match, scan_points, transform_points
    from aiorobot.sim import World
    from aiorobot.sim._sensors import LidarModel

    n = 5 if quick else 50
    out: dict[str, Any] = {}
    world, lidar, rng = World.load("warehouse"), LidarModel(), np.random.default_rng(2)

    def points(p: tuple[float, float, float]) -> np.ndarray:
        return scan_points(lidar.measure(world, *p, rng).astype(np.float64), lidar.angle_min, lidar.angle_increment,
                           lidar.range_min, lidar.range_max)

    reference = np.vstack([transform_points(q, points(q)) for q in [(-1.0 + 0.5 * i, -5.0, 0.0) for i in range(10)]])
    scan = points((4.2, -5.0, 0.02))
    for key, res, sd in (("slam_match_005_us", 0.05, 0.05), ("slam_match_default_us", 0.025, 0.03)):
        out[key] = _timed(lambda: match(reference, scan, (4.25, -4.97, 0.0), resolution=res, smear_deviation=sd,
                                        linear_half=0.25, angular_half=0.349), n)
    # a 500-node loop (0.5 m apart on a 40 m circle), 2 % drift in its chain, closed by ten closures
    truth = [(40.0 * math.cos(a), 40.0 * math.sin(a), a + math.pi / 2) for a in np.linspace(0, 2 * math.pi, 500, endpoint=False)]
    graph = PoseGraph()
    pose = truth[0]
    graph.add_node(pose)
    noise = np.random.default_rng(3)
    for k in range(1, 500):
        z = relative(truth[k - 1], truth[k])
        z = (z[0] * 1.02 + noise.normal(0, 0.005), z[1] + noise.normal(0, 0.005), z[2] * 1.01 + noise.normal(0, 0.002))
        pose = compose(pose, z)
        graph.add_node(pose)
        graph.add_edge(k - 1, k, z, np.diag([1e-4, 1e-4, 3e-5]), "scan_match")
    for j in range(10):
        graph.add_edge(j, 490 + j, relative(truth[j], truth[490 + j]), np.diag([4e-4, 4e-4, 1e-4]), "loop_closure")
    start = graph.poses.copy()

    def optimise() -> None:
        graph.poses = start.copy()
        graph.optimize()

    out["slam_optimise_500_us"] = _timed(optimise, max(3, n // 5))
    route = WAREHOUSE_LOOP[:1] if quick else WAREHOUSE_LOOP
    run = scripted_mapping_run(world, WAREHOUSE_START, route, step=0.05)  # 10 Hz scans at 0.5 m/s
    sim_sec = len(run.truth) / 10.0
    out["slam_mapping_run"] = {"sim_sec": sim_sec, "wall_sec": run.total_sec, "slam_sec": run.slam_sec,
                               "real_time_factor": sim_sec / max(run.total_sec, 1e-9), "nodes": len(run.slam.graph),
                               "loop_closures": run.slam.statistics().loop_closures}
    return out


def _collision_monitor_step() -> Any:
    """A scan of 360 beams (a room 1.5-4 m away, seeded) to base-frame points, then Nav2's default zones decide a command."""
    from aiorobot.nav import ActionType, CollisionMonitor, Zone

    monitor = CollisionMonitor([
        Zone("PolygonStop", ActionType.STOP, vertices=[[0.3, 0.3], [0.3, -0.3], [0.0, -0.3], [0.0, 0.3]], min_points=4),
        Zone("PolygonSlow", ActionType.SLOWDOWN, vertices=[[0.4, 0.4], [0.4, -0.4], [-0.4, -0.4], [-0.4, 0.4]], slowdown_ratio=0.3),
        Zone("FootprintApproach", ActionType.APPROACH, vertices=[[0.25, 0.2], [0.25, -0.2], [-0.25, -0.2], [-0.25, 0.2]],
             min_points=6, time_before_collision=2.0, simulation_time_step=0.1),
    ])
    ranges = np.random.default_rng(2).uniform(1.5, 4.0, 360)
    angles = np.linspace(-math.pi, math.pi, 360, endpoint=False)
    laser = np.eye(4)
    laser[0, 3] = 0.1

    def step() -> None:
        pts = np.column_stack([ranges * np.cos(angles), ranges * np.sin(angles), np.zeros(360)]) @ laser[:3, :3].T + laser[:3, 3]
        monitor.decide((0.5, 0.0, 0.3), {"scan": np.ascontiguousarray(pts[:, :2])})

    return step


def table(part: dict[str, Any]) -> Any:
    rows = [
        ("A* 400x400 costmap, corner to corner (target <= 20 ms)", part["astar_400x400_us"]),
        ("plan incl. line-of-sight smoothing", part["plan_with_smoothing_us"]),
        ("AMCL update, 500 particles x 60 beams (target <= 5 ms)", part["amcl_500x60_us"]),
        ("costmap update from one 360-beam scan (target <= 2 ms)", part["costmap_scan_update_us"]),
        ("Regulated Pure Pursuit step", part["rpp_step_us"]),
        ("MPPI control cycle, 1000 x 56 (target <= 20 ms p99)", part["mppi_cycle_us"]),
        ("SLAM scan match, 360 beams at 0.05 m (target <= 5 ms)", part["slam_match_005_us"]),
        ("SLAM scan match, 360 beams at the default 0.025 m", part["slam_match_default_us"]),
        ("SLAM loop-closure optimisation, 500 nodes (target <= 50 ms)", part["slam_optimise_500_us"]),
    ]
    if "collision_monitor_scan_us" in part:  # parts recorded before the monitor existed lack it
        rows.append(("collision monitor, one 360-beam scan (target <= 2 ms)", part["collision_monitor_scan_us"]))
    run = part["slam_mapping_run"]
    return figure_table("navigation cores (ms)", ("figure", "p50", "p99", "max"),
                        [(name, s["p50_us"] / 1e3, s["p99_us"] / 1e3, s["max_us"] / 1e3) for name, s in rows],
                        caption=f"SLAM mapping run (simulated lidar + SLAM, {run['sim_sec']:.0f} s of 10 Hz scans, "
                        f"{run['nodes']} nodes, {run['loop_closures']} loop closures): {run['real_time_factor']:.1f}x "
                        f"real time (target >= 5x)")
