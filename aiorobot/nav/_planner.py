"""Global planning on a costmap: A* (NavFn-like costs, 8-connected) and path smoothing.

``plan(costmap, start_xy, goal_xy)`` returns the path as world points (N, 2) through cell
centres, shortened by line-of-sight where that never raises the peak cost along the way, then
resampled at the costmap's resolution, with a yaw per point (the heading to the next point; the
last takes the goal's yaw when given). A polygon footprint on the costmap must fit at every pose.
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ._costmap import INSCRIBED_INFLATED_OBSTACLE, NO_INFORMATION, Costmap

__all__ = ["PlanError", "PlanFailure", "Plan", "plan"]


class PlanFailure(enum.Enum):
    """Why :func:`plan` found no path. Each name is the nav2_msgs ``ComputePathToPose.Result``
    error code that says it (``getattr(ComputePathToPose.Result, kind.name)``)."""

    START_OUTSIDE_MAP = "the start is outside the map"
    GOAL_OUTSIDE_MAP = "the goal is outside the map"
    GOAL_OCCUPIED = "the goal is in or too close to an obstacle"
    NO_VALID_PATH = "no path joins the start to the goal"


class PlanError(Exception):
    """No path: the start or goal is outside the map or in an obstacle, or the goal is unreachable.

    ``kind`` (a :class:`PlanFailure`) says which, for code; the message says it for people.
    """

    def __init__(self, message: str, kind: PlanFailure = PlanFailure.NO_VALID_PATH) -> None:
        super().__init__(message)
        self.kind = kind


@dataclass(frozen=True)
class Plan:
    """A planned path: ``poses`` (N, 3) as (x, y, yaw) in the costmap's frame, its length and search cost."""

    poses: NDArray[np.float64]
    length_m: float
    cost: float


def _blocked(value: int, allow_unknown: bool) -> bool:
    return value >= INSCRIBED_INFLATED_OBSTACLE and not (value == NO_INFORMATION and allow_unknown)


def plan(costmap: Costmap, start_xy: tuple[float, float], goal_xy: tuple[float, float], *, goal_yaw: float | None = None,
         neutral_cost: float = 1.0, cost_factor: float = 3.0, allow_unknown: bool = True, smooth: bool = True) -> Plan:
    """A* from ``start_xy`` to ``goal_xy`` (world, m). Raises PlanError saying why when there is no path.

    With a polygon footprint on the costmap every pose is checked in the path's heading
    (:meth:`Costmap.in_collision`); cells where it does not fit are left out and the search runs
    again (Nav2's 2D planners check the centre cell only, its IsPathValid the footprint).
    """
    sr, sc = costmap.world_to_cell(*start_xy)
    gr, gc = costmap.world_to_cell(*goal_xy)
    for what, (r, c), xy in (("start", (sr, sc), start_xy), ("goal", (gr, gc), goal_xy)):
        if not costmap.in_bounds(r, c):
            kind = PlanFailure.START_OUTSIDE_MAP if what == "start" else PlanFailure.GOAL_OUTSIDE_MAP
            raise PlanError(f"the {what} ({xy[0]:.2f}, {xy[1]:.2f}) is outside the map", kind)
    if _blocked(int(costmap.cost[gr, gc]), allow_unknown):
        raise PlanError(f"the goal ({goal_xy[0]:.2f}, {goal_xy[1]:.2f}) is in or too close to an obstacle (cost {int(costmap.cost[gr, gc])})",
                        PlanFailure.GOAL_OCCUPIED)
    cost = costmap.cost
    if _blocked(int(cost[sr, sc]), allow_unknown):  # a start inside inflation: plan out of it as Nav2 planners do
        cost = cost.copy()
        cost[sr, sc] = INSCRIBED_INFLATED_OBSTACLE - 1
    blocked = 0
    for _ in range(_FOOTPRINT_ROUNDS):
        poses, total = _search(costmap, cost, (sr, sc), (gr, gc), start_xy, goal_xy, goal_yaw, neutral_cost, cost_factor,
                               allow_unknown, smooth)
        hits = _footprint_hits(costmap, poses, allow_unknown)
        if not len(hits):
            seg = np.linalg.norm(np.diff(poses[:, :2], axis=0), axis=1) if len(poses) > 1 else np.zeros(0)
            return Plan(poses, float(seg.sum()), float(total))
        # the polygon footprint touches an obstacle there (in the path's heading): keep the search out of those cells
        if cost is costmap.cost:
            cost = cost.copy()
        before = blocked
        for x, y, yaw in poses[hits]:
            blocked += _block_around(costmap, cost, x, y, yaw, ((sr, sc), (gr, gc)))
        if blocked == before:  # only the goal's pose is left: the footprint does not fit there in the goal's yaw
            break
    raise PlanError(f"no path from ({start_xy[0]:.2f}, {start_xy[1]:.2f}) to ({goal_xy[0]:.2f}, {goal_xy[1]:.2f}) that the robot's "
                    f"footprint fits along ({blocked} cells where it touches an obstacle left out in {_FOOTPRINT_ROUNDS} searches)",
                    PlanFailure.NO_VALID_PATH)


#: searches :func:`plan` makes for a polygon footprint before it gives up
_FOOTPRINT_ROUNDS = 8


def _search(costmap: Costmap, cost: NDArray[np.uint8], start: tuple[int, int], goal: tuple[int, int], start_xy: tuple[float, float],
            goal_xy: tuple[float, float], goal_yaw: float | None, neutral_cost: float, cost_factor: float, allow_unknown: bool,
            smooth: bool) -> tuple[NDArray[np.float64], float]:
    """A* on ``cost``, smoothed and resampled: poses (N, 3) and the search cost."""
    from ._kernels import astar

    cells, total = astar(cost, start[0], start[1], goal[0], goal[1], float(neutral_cost), float(cost_factor), bool(allow_unknown))
    if cells.shape[0] == 0:
        raise PlanError(f"no path from ({start_xy[0]:.2f}, {start_xy[1]:.2f}) to ({goal_xy[0]:.2f}, {goal_xy[1]:.2f}): the goal is unreachable",
                        PlanFailure.NO_VALID_PATH)
    if smooth and cells.shape[0] > 2:
        cells = shortcut(cost, cells)
    # cell centres, as Costmap.cell_to_world, for the whole path at once
    xy = np.column_stack([costmap.origin[0] + (cells[:, 1] + 0.5) * costmap.resolution,
                          costmap.origin[1] + (cells[:, 0] + 0.5) * costmap.resolution]).astype(np.float64)
    xy[0] = start_xy
    xy[-1] = goal_xy
    xy = resample(xy, costmap.resolution)
    yaw = np.empty(len(xy))
    if len(xy) > 1:
        d = np.diff(xy, axis=0)
        yaw[:-1] = np.arctan2(d[:, 1], d[:, 0])
        yaw[-1] = yaw[-2] if goal_yaw is None else goal_yaw
    else:
        yaw[:] = 0.0 if goal_yaw is None else goal_yaw
    return np.column_stack([xy, yaw]), float(total)


def _block_around(costmap: Costmap, cost: NDArray[np.uint8], x: float, y: float, yaw: float, keep: tuple[tuple[int, int], ...]) -> int:
    """Block the cells near (x, y) where the footprint in heading ``yaw`` touches an obstacle (the whole
    width of a gap it does not fit, in one go); returns how many were newly blocked."""
    assert costmap.footprint is not None
    reach = int(math.ceil(costmap.footprint.circumscribed_radius / costmap.resolution))
    r0, c0 = costmap.world_to_cell(x, y)
    count = 0
    for r in range(max(r0 - reach, 0), min(r0 + reach + 1, costmap.shape[0])):
        for c in range(max(c0 - reach, 0), min(c0 + reach + 1, costmap.shape[1])):
            if (r, c) in keep or cost[r, c] >= INSCRIBED_INFLATED_OBSTACLE:
                continue
            if costmap.in_collision(*costmap.cell_to_world(r, c), yaw):
                cost[r, c] = INSCRIBED_INFLATED_OBSTACLE
                count += 1
    return count


def _footprint_hits(costmap: Costmap, poses: NDArray[np.float64], allow_unknown: bool) -> NDArray[np.int64]:
    """Indices of the poses (x, y, yaw) where a polygon footprint touches an obstacle (none for a round one:
    inflation by its radius already keeps the search clear). The first pose (the robot, where it is) is not checked."""
    if costmap.footprint is None or costmap.footprint.is_circular:
        return np.zeros(0, dtype=np.int64)
    return np.array([i for i in range(1, len(poses)) if costmap.in_collision(*poses[i], allow_unknown=allow_unknown)], dtype=np.int64)


def shortcut(cost: NDArray[np.uint8], cells: NDArray[np.int64], max_skip: int = 400) -> NDArray[np.int64]:
    """Replace runs of the path by straight segments where the segment's peak cost is no higher
    than the replaced run's (so smoothing never pulls the path closer to obstacles)."""
    from ._kernels import shortcut as kernel

    return kernel(np.ascontiguousarray(cost), np.ascontiguousarray(cells, dtype=np.int64), int(max_skip))


def resample(xy: NDArray[np.float64], spacing: float) -> NDArray[np.float64]:
    """Points every ``spacing`` metres along the polyline ``xy`` (N, 2), keeping both ends."""
    if len(xy) < 2:
        return xy.copy()
    seg = np.linalg.norm(np.diff(xy, axis=0), axis=1)
    s = np.concatenate([[0.0], np.cumsum(seg)])
    if s[-1] <= 0:
        return xy[:1].copy()
    count = max(2, int(math.ceil(s[-1] / spacing)) + 1)
    t = np.linspace(0.0, s[-1], count)
    return np.column_stack([np.interp(t, s, xy[:, 0]), np.interp(t, s, xy[:, 1])])
