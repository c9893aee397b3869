"""Costmap inflation against Nav2's cost function; A* optimality on mazes; plan errors."""

from __future__ import annotations

import heapq
import math

import numpy as np
import pytest

from aiorobot.nav import Costmap, PlanError, plan
from aiorobot.nav._costmap import INSCRIBED_INFLATED_OBSTACLE, LETHAL_OBSTACLE, NO_INFORMATION, inflation_cost
from aiorobot.nav._kernels import astar


def test_inflation_follows_nav2s_cost_function_around_one_lethal_cell() -> None:
    # nav2_costmap_2d InflationLayer::computeCost with robot_radius 0.22, inflation_radius 0.55, factor 3.
    static = np.zeros((41, 41), dtype=np.uint8)
    static[20, 20] = LETHAL_OBSTACLE
    cm = Costmap(static, 0.05, (0.0, 0.0), robot_radius=0.22, inflation_radius=0.55, cost_scaling_factor=3.0)
    assert cm.cost[20, 20] == LETHAL_OBSTACLE
    for k in range(1, 20):
        d = k * 0.05
        got = int(cm.cost[20, 20 + k])
        if d <= 0.22:
            assert got == INSCRIBED_INFLATED_OBSTACLE, k
        elif d <= 0.55 + 1e-9:
            assert got == int(math.floor(252 * math.exp(-3.0 * (d - 0.22)))), k
        else:
            assert got == 0, k
    # diagonal distances are Euclidean between cell centres
    d = math.hypot(6, 6) * 0.05
    assert cm.cost[26, 26] == int(math.floor(252 * math.exp(-3.0 * (d - 0.22))))


def test_inflation_cost_function_endpoints() -> None:
    assert inflation_cost(0.0, 0.2, 3.0) == LETHAL_OBSTACLE
    assert inflation_cost(0.2, 0.2, 3.0) == INSCRIBED_INFLATED_OBSTACLE
    assert inflation_cost(0.2 + 1e-6, 0.2, 3.0) == 251  # just outside the inscribed radius: floor(252 * ~1)


def test_inflation_radius_smaller_than_the_robot_is_refused() -> None:
    with pytest.raises(ValueError, match=r"inflation_radius \(0.1\) must be >= robot_radius \(0.22\)"):
        Costmap(np.zeros((5, 5), np.uint8), 0.05, (0, 0), robot_radius=0.22, inflation_radius=0.1)


def _dijkstra(blocked: np.ndarray, start: tuple[int, int], goal: tuple[int, int]) -> float:
    """Oracle: 8-connected shortest path, no corner cutting, unit/sqrt2 steps."""
    h, w = blocked.shape
    dist = {start: 0.0}
    heap = [(0.0, start)]
    while heap:
        d, (r, c) = heapq.heappop(heap)
        if (r, c) == goal:
            return d
        if d > dist.get((r, c), math.inf):
            continue
        for dr in (-1, 0, 1):
            for dc in (-1, 0, 1):
                if dr == dc == 0:
                    continue
                nr, nc = r + dr, c + dc
                if not (0 <= nr < h and 0 <= nc < w) or blocked[nr, nc]:
                    continue
                if dr and dc and (blocked[r, nc] or blocked[nr, c]):
                    continue
                nd = d + (math.sqrt(2) if dr and dc else 1.0)
                if nd < dist.get((nr, nc), math.inf):
                    dist[(nr, nc)] = nd
                    heapq.heappush(heap, (nd, (nr, nc)))
    return math.inf


def _maze(seed: int, size: int = 41) -> np.ndarray:
    """A random maze (recursive backtracker on odd cells), seeded."""
    rng = np.random.default_rng(seed)
    grid = np.ones((size, size), dtype=bool)
    stack = [(1, 1)]
    grid[1, 1] = False
    while stack:
        r, c = stack[-1]
        options = [(r + dr, c + dc, dr, dc) for dr, dc in ((0, 2), (0, -2), (2, 0), (-2, 0))
                   if 0 < r + dr < size - 1 and 0 < c + dc < size - 1 and grid[r + dr, c + dc]]
        if not options:
            stack.pop()
            continue
        nr, nc, dr, dc = options[rng.integers(len(options))]
        grid[r + dr // 2, c + dc // 2] = False
        grid[nr, nc] = False
        stack.append((nr, nc))
    # open a few extra walls so there are loops and diagonal shortcuts
    walls = np.argwhere(grid[1:-1, 1:-1]) + 1
    for r, c in walls[rng.choice(len(walls), size=len(walls) // 8, replace=False)]:
        grid[r, c] = False
    return grid


@pytest.mark.parametrize("seed", [1, 2, 3, 4])
def test_astar_is_optimal_on_mazes(seed: int) -> None:
    blocked = _maze(seed)
    cost = np.where(blocked, LETHAL_OBSTACLE, 0).astype(np.uint8)
    free = np.argwhere(~blocked)
    start, goal = tuple(free[0]), tuple(free[-1])
    path, total = astar(cost, start[0], start[1], goal[0], goal[1], 1.0, 3.0, True)
    assert total == pytest.approx(_dijkstra(blocked, start, goal), abs=1e-9)
    assert tuple(path[0]) == start and tuple(path[-1]) == goal
    steps = np.abs(np.diff(path, axis=0))
    assert np.all(steps.max(axis=1) == 1)  # neighbours only
    assert not blocked[path[:, 0], path[:, 1]].any()


def _weighted_dijkstra(cost: np.ndarray, start: tuple[int, int], goal: tuple[int, int], allow_unknown: bool) -> float:
    """The planner's step cost, by plain Dijkstra: length * (1 + 3 * cost / 252), unknown as free when allowed."""
    h, w = cost.shape
    open_ = (cost < INSCRIBED_INFLATED_OBSTACLE) | ((cost == NO_INFORMATION) & allow_unknown)
    cell = np.where(cost == NO_INFORMATION, 1.0, 1.0 + 3.0 * cost.astype(float) / 252.0)
    dist = {start: 0.0}
    heap = [(0.0, start)]
    while heap:
        d, (r, c) = heapq.heappop(heap)
        if (r, c) == goal:
            return d
        if d > dist.get((r, c), math.inf):
            continue
        for dr in (-1, 0, 1):
            for dc in (-1, 0, 1):
                nr, nc = r + dr, c + dc
                if (dr == dc == 0) or not (0 <= nr < h and 0 <= nc < w) or not open_[nr, nc]:
                    continue
                if dr and dc and not (open_[r, nc] and open_[nr, c]):
                    continue
                nd = d + (math.sqrt(2) if dr and dc else 1.0) * cell[nr, nc]
                if nd < dist.get((nr, nc), math.inf):
                    dist[(nr, nc)] = nd
                    heapq.heappush(heap, (nd, (nr, nc)))
    return math.inf


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("allow_unknown", [True, False])
def test_astar_is_optimal_on_weighted_grids_with_unknown_space(seed: int, allow_unknown: bool) -> None:
    rng = np.random.default_rng(seed)
    h, w = rng.integers(8, 40, 2)
    cost = (rng.random((h, w)) * 253).astype(np.uint8)  # 0..252: free with a cost
    cost[rng.random((h, w)) < 0.2] = LETHAL_OBSTACLE
    cost[rng.random((h, w)) < 0.1] = NO_INFORMATION
    start, goal = (0, 0), (h - 1, w - 1)
    cost[start] = cost[goal] = 0
    path, total = astar(cost, 0, 0, h - 1, w - 1, 1.0, 3.0, allow_unknown)
    expected = _weighted_dijkstra(cost, start, goal, allow_unknown)
    if math.isinf(expected):
        assert len(path) == 0 and math.isinf(total)
        return
    assert total == pytest.approx(expected, rel=1e-12)
    assert tuple(path[0]) == start and tuple(path[-1]) == goal
    assert np.all(np.abs(np.diff(path, axis=0)).max(axis=1) == 1)
    cells = cost[path[:, 0], path[:, 1]]
    assert not ((cells >= INSCRIBED_INFLATED_OBSTACLE) & ~((cells == NO_INFORMATION) & allow_unknown)).any()


def test_plan_keeps_clear_of_obstacles_and_reports_why_it_cannot() -> None:
    static = np.zeros((80, 80), dtype=np.uint8)
    static[:, 0] = static[:, -1] = static[0, :] = static[-1, :] = LETHAL_OBSTACLE
    static[:60, 40] = LETHAL_OBSTACLE  # a wall with a gap at the top
    cm = Costmap(static, 0.05, (0.0, 0.0))
    p = plan(cm, (0.5, 0.5), (3.5, 0.5), goal_yaw=0.5)
    assert p.poses[0, :2] == pytest.approx([0.5, 0.5]) and p.poses[-1, :2] == pytest.approx([3.5, 0.5])
    assert p.poses[-1, 2] == 0.5
    assert max(cm.cost_at(x, y) for x, y in p.poses[:, :2]) < INSCRIBED_INFLATED_OBSTACLE
    assert p.length_m > 2 * math.hypot(1.5, 2.8)  # up over the wall end at y = 3 and down again
    with pytest.raises(PlanError, match=r"the goal \(2.00, 1.00\) is in or too close to an obstacle"):
        plan(cm, (0.5, 0.5), (2.0, 1.0))
    with pytest.raises(PlanError, match="outside the map"):
        plan(cm, (0.5, 0.5), (9.0, 0.5))
    static[60:, 40] = LETHAL_OBSTACLE  # close the gap
    with pytest.raises(PlanError, match="unreachable"):
        plan(Costmap(static, 0.05, (0.0, 0.0)), (0.5, 0.5), (3.5, 0.5))


def test_unknown_space_is_planned_through_only_when_allowed() -> None:
    static = np.full((20, 20), NO_INFORMATION, dtype=np.uint8)
    static[:, :3] = 0
    static[:, 17:] = 0
    cm = Costmap(static, 0.1, (0.0, 0.0))
    plan(cm, (0.1, 0.1), (1.9, 0.1), allow_unknown=True)
    with pytest.raises(PlanError, match="unreachable"):
        plan(cm, (0.1, 0.1), (1.9, 0.1), allow_unknown=False)


def test_obstacle_layer_marks_hits_and_clears_along_beams() -> None:
    cm = Costmap(np.zeros((40, 40), np.uint8), 0.05, (0.0, 0.0))
    cm.obstacles[10, 20] = LETHAL_OBSTACLE  # an old obstacle in the way of the beam
    cm.mark_scan((0.25, 0.525), np.array([[1.5, 0.525], [1.0, 1.5]]), np.array([True, False]))
    cm.update()
    assert cm.obstacles[10, 30] == LETHAL_OBSTACLE  # the hit at x=1.5
    assert cm.obstacles[10, 20] == 0  # cleared by the beam passing through it
    assert cm.cost_at(1.5, 0.525) == LETHAL_OBSTACLE


def test_each_planner_failure_has_its_kind_and_nav2s_named_result_code() -> None:
    from aiorobot.msgs.nav2_msgs import ComputePathToPose
    from aiorobot.nav import PlanFailure

    static = np.zeros((40, 40), dtype=np.uint8)
    static[:, 20] = LETHAL_OBSTACLE  # a wall across the whole map
    cm = Costmap(static, 0.05, (0.0, 0.0))
    cases = {
        PlanFailure.START_OUTSIDE_MAP: ((-1.0, 0.5), (0.5, 0.5)),
        PlanFailure.GOAL_OUTSIDE_MAP: ((0.5, 0.5), (0.5, 9.0)),
        PlanFailure.GOAL_OCCUPIED: ((0.5, 0.5), (1.02, 0.5)),
        PlanFailure.NO_VALID_PATH: ((0.5, 0.5), (1.6, 0.5)),
    }
    for kind, (start, goal) in cases.items():
        with pytest.raises(PlanError) as err:
            plan(cm, start, goal)
        assert err.value.kind is kind, str(err.value)
    codes = {kind: getattr(ComputePathToPose.Result, kind.name) for kind in PlanFailure}
    assert codes == {PlanFailure.START_OUTSIDE_MAP: 203, PlanFailure.GOAL_OUTSIDE_MAP: 204,
                     PlanFailure.GOAL_OCCUPIED: 206, PlanFailure.NO_VALID_PATH: 208}


def test_navigation_failures_carry_nav2s_navigate_to_pose_codes() -> None:
    from aiorobot.nav import NavigationFailure

    assert {k.name: k.code for k in NavigationFailure} == {"UNKNOWN": 9000, "FAILED_TO_LOAD_BEHAVIOR_TREE": 9001, "TF_ERROR": 9002}
