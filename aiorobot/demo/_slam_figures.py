"""SLAM against the simulator's world: how well a built map agrees with it (the demo's, the bench's and
the tests' yardstick), and a scripted mapping run (a route, wheel odometry with a scale error, simulated
scans fed to :class:`~aiorobot.nav.Slam`) that the tests and the bench share."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = ["WAREHOUSE_LOOP", "WAREHOUSE_START", "MapAgreement", "ScriptedRun", "map_agreement", "route_poses",
           "scripted_mapping_run", "wheel_odometry"]

#: a loop of the warehouse (~48 m): east through the south-west room's door, up the aisle between the
#: shelf rows, west along the north side, through the north-west room and its inner door, home and on
WAREHOUSE_START = (-8.0, -5.0, 0.0)
WAREHOUSE_LOOP = [(-1.5, -5.0), (4.75, -5.0), (4.75, 5.25), (-1.5, 5.25), (-1.5, 4.2), (-6.5, 4.2), (-6.6, -2.0),
                  (-8.0, -5.0), (-5.0, -5.0)]


def route_poses(start: tuple[float, float, float], waypoints: list[tuple[float, float]], step: float = 0.1,
                turn: float = 0.1) -> NDArray[np.float64]:
    """True poses (N, 3) every ``step`` m / ``turn`` rad: turn on the spot to face each waypoint, drive to it."""
    x, y, th = start
    poses = [start]
    for wx, wy in waypoints:
        d = (math.atan2(wy - y, wx - x) - th + math.pi) % (2 * math.pi) - math.pi
        n = int(math.ceil(abs(d) / turn))
        for _ in range(n):
            th += d / n
            poses.append((x, y, th))
        n = int(math.ceil(math.hypot(wx - x, wy - y) / step))
        for k in range(n):
            x += (wx - x) / (n - k)
            y += (wy - y) / (n - k)
            poses.append((x, y, th))
    return np.array(poses)


def wheel_odometry(truth: NDArray[np.float64], scale_error: float, noise: float, seed: int) -> NDArray[np.float64]:
    """Odometry (odom frame, from zero) of ``truth``: each step's motion scaled by 1 + scale_error and by
    1 + N(0, noise) per axis, as the simulator's RobotBody integrates it."""
    from aiorobot.nav._slam_graph import relative

    rng = np.random.default_rng(seed)
    out = [(0.0, 0.0, 0.0)]
    for a, b in zip(truth[:-1], truth[1:]):
        step = np.array(relative(tuple(a), tuple(b))) * (1 + scale_error) * (1 + rng.normal(0, noise, 3))
        ox, oy, oth = out[-1]
        c, s = math.cos(oth), math.sin(oth)
        out.append((ox + c * step[0] - s * step[1], oy + s * step[0] + c * step[1], oth + step[2]))
    return np.array(out)


@dataclass
class ScriptedRun:
    """A scripted mapping run: the SLAM core after it, the truth and odometry per scan, the estimates
    (map -> base_link after each scan), the scan index each graph node was made from, the CPU time."""

    slam: Any
    world: Any
    truth: NDArray[np.float64]
    odom: NDArray[np.float64]
    estimates: NDArray[np.float64]
    node_scans: list[int]
    slam_sec: float
    total_sec: float


def scripted_mapping_run(world: Any, start: tuple[float, float, float], waypoints: list[tuple[float, float]],
                         params: Any = None, *, seed: int = 0, scale_error: float = 0.03, step: float = 0.1) -> ScriptedRun:
    """Scans every ``step`` m along the route (lidar: the simulator's, seeded), fed to a fresh Slam."""
    import time

    from aiorobot.nav import Slam
    from aiorobot.sim._sensors import LidarModel

    truth = route_poses(start, waypoints, step=step)
    odom = wheel_odometry(truth, scale_error, 0.01, seed)
    lidar, rng = LidarModel(), np.random.default_rng(seed + 1)
    slam = Slam(params, start_pose=start)
    estimates, nodes = [], []
    slam_sec, t0 = 0.0, time.perf_counter()
    for k, (p, o) in enumerate(zip(truth, odom)):
        ranges = lidar.measure(world, p[0], p[1], p[2], rng)
        t1 = time.perf_counter()
        update = slam.add_scan(tuple(o), ranges, lidar.angle_min, lidar.angle_increment, lidar.range_min, lidar.range_max)
        slam_sec += time.perf_counter() - t1
        estimates.append(slam.pose)
        if update.node >= 0:
            nodes.append(k)
    return ScriptedRun(slam, world, truth, odom, np.array(estimates), nodes, slam_sec, time.perf_counter() - t0)


@dataclass(frozen=True, slots=True)
class MapAgreement:
    """``precision``: share of the built map's occupied cells within ``tolerance_m`` of a true wall;
    ``recall``: share of the wall cells the route's scans reached that the built map marks occupied
    (within one cell: a beam ends on the face between a wall cell and the free one before it)."""

    precision: float
    recall: float
    occupied_cells: int
    seen_wall_cells: int
    tolerance_m: float


def map_agreement(grid: Any, world: Any, route_xy: NDArray[np.float64], *, tolerance_m: float = 0.1,
                  beams: int = 360, range_max: float = 12.0) -> MapAgreement:
    """Compare ``grid`` (an :class:`~aiorobot.nav.OccupancyMap` in the world's frame) with ``world``
    (an :class:`~aiorobot.sim.World`); ``route_xy`` (N, 2): where the robot's lidar looked from."""
    from aiorobot.sim._raycast import raycast

    data, res = np.asarray(grid.data), float(grid.resolution)
    ox, oy = float(grid.origin[0]), float(grid.origin[1])
    wres, (wox, woy) = float(world.resolution), world.origin[:2]
    wh, ww = world.occupied.shape
    rows, cols = np.nonzero(data == 100)
    cx, cy = ox + (cols + 0.5) * res, oy + (rows + 0.5) * res
    wr = np.floor((cy - woy) / wres).astype(np.int64)
    wc = np.floor((cx - wox) / wres).astype(np.int64)
    inside = (wr >= 0) & (wc >= 0) & (wr < wh) & (wc < ww)
    near = np.zeros(len(rows), dtype=bool)
    # clearance: cells from each cell centre to the nearest occupied cell centre
    near[inside] = world.clearance[wr[inside], wc[inside]] * wres <= tolerance_m
    angles = -np.pi + 2.0 * np.pi * np.arange(beams) / beams
    seen: set[tuple[int, int]] = set()
    for x, y in np.asarray(route_xy, dtype=np.float64).reshape(-1, 2):
        r = raycast(world.occupied, wres, (wox, woy), (x, y), angles, range_max, clearance=world.clearance)
        ok = np.isfinite(r)
        hx = x + (r[ok] + 0.5 * wres) * np.cos(angles[ok])  # half a cell past the face: inside the wall cell
        hy = y + (r[ok] + 0.5 * wres) * np.sin(angles[ok])
        hr = np.floor((hy - woy) / wres).astype(np.int64)
        hc = np.floor((hx - wox) / wres).astype(np.int64)
        seen.update(zip(hr.tolist(), hc.tolist()))
    cells = np.array(sorted(seen), dtype=np.int64).reshape(-1, 2)
    cells = cells[(cells[:, 0] >= 0) & (cells[:, 1] >= 0) & (cells[:, 0] < wh) & (cells[:, 1] < ww)]
    cells = cells[world.occupied[cells[:, 0], cells[:, 1]] == 1]
    occupied = np.pad(data == 100, 1)  # a one-cell border of False: the 3 x 3 window never leaves the grid
    br = np.floor((woy + (cells[:, 0] + 0.5) * wres - oy) / res).astype(np.int64) + 1
    bc = np.floor((wox + (cells[:, 1] + 0.5) * wres - ox) / res).astype(np.int64) + 1
    ok = (br >= 1) & (bc >= 1) & (br <= data.shape[0]) & (bc <= data.shape[1])
    marked = np.zeros(len(cells), dtype=bool)
    for dr in (-1, 0, 1):
        for dc in (-1, 0, 1):
            marked[ok] |= occupied[br[ok] + dr, bc[ok] + dc]
    return MapAgreement(float(near.mean()) if len(near) else 0.0, float(marked.mean()) if len(marked) else 0.0,
                        int(len(rows)), int(len(cells)), tolerance_m)
