"""Costmap filters (nav2_costmap_2d's keepout and speed filters, Nav2's mask and filter-info convention):
the pure pieces, and the navigation server honouring both in the simulator."""

from __future__ import annotations

import asyncio
import math
from typing import Any

import numpy as np
import pytest

from aiorobot import Node, Runtime
from aiorobot.nav import Costmap, NavigationServer, Navigator, OccupancyMap, RegulatedPurePursuit, RppParameters, plan, pose_stamped
from aiorobot.nav._costmap import LETHAL_OBSTACLE, NO_INFORMATION
from aiorobot.nav._filters import NO_SPEED_LIMIT, FilterType, SpeedLimitFilter, keepout_layer, mask_cost

from .test_collision_monitor_sim import send_map_to_odom, simulator


def _mask(boxes: list[tuple[float, float, float, float, int]], resolution: float = 0.1) -> OccupancyMap:
    """A mask over the box world (-3.5..3.5 m), 0 everywhere but ``value`` in each (x0, x1, y0, y1, value)."""
    n = int(round(7.0 / resolution))
    data = np.zeros((n, n), np.int8)
    centres = -3.5 + (np.arange(n) + 0.5) * resolution
    for x0, x1, y0, y1, value in boxes:
        data[np.ix_((centres >= y0) & (centres <= y1), (centres >= x0) & (centres <= x1))] = value
    return OccupancyMap(data, resolution, (-3.5, -3.5, 0.0))


#: a keepout band across the straight route from (-2, 0) to (2.5, 0), open below y = -1.2
KEEPOUT = (-0.3, 0.3, -1.2, 3.5, 100)
#: a speed zone at 40 % over the last stretch
SPEED_ZONE = (1.0, 3.5, -3.5, 3.5, 40)


def _gap_to_keepout(xy: np.ndarray) -> np.ndarray:
    x0, x1, y0, y1, _ = KEEPOUT
    dx = np.maximum(np.maximum(x0 - xy[:, 0], xy[:, 0] - x1), 0.0)
    dy = np.maximum(np.maximum(y0 - xy[:, 1], xy[:, 1] - y1), 0.0)
    return np.hypot(dx, dy)


def test_mask_values_become_costs_as_nav2_get_mask_cost() -> None:
    assert mask_cost(np.array([0, 1, 50, 99, 100, -1], np.int8)).tolist() == [0, 3, 127, 251, LETHAL_OBSTACLE, NO_INFORMATION]


def _room() -> Costmap:
    static = np.zeros((140, 140), np.uint8)
    static[0, :] = static[-1, :] = static[:, 0] = static[:, -1] = LETHAL_OBSTACLE
    return Costmap(static, 0.05, (-3.5, -3.5))


def test_keepout_across_the_shortest_route_makes_the_path_go_around() -> None:
    cm = _room()
    straight = plan(cm, (-2.0, 0.0), (2.5, 0.0))
    assert np.abs(straight.poses[:, 1]).max() < 0.05
    cm.set_keepout(keepout_layer(cm, _mask([KEEPOUT])))  # a mask at another resolution than the costmap's
    around = plan(cm, (-2.0, 0.0), (2.5, 0.0))
    # the keepout is inflated as an obstacle: the robot's disc (0.22 m) stays out, not only its centre
    assert _gap_to_keepout(around.poses[:, :2]).min() > 0.22 - 0.05 and around.poses[:, 1].min() < -1.2
    # the keepout survives obstacle updates, and a goal inside it is occupied
    cm.update()
    assert cm.cost_at(0.0, 0.0) == LETHAL_OBSTACLE
    cm.set_keepout(None)
    assert cm.cost_at(0.0, 0.0) == 0


def test_speed_filter_limits_in_percent_or_metres_per_second_and_zero_means_none() -> None:
    pct = SpeedLimitFilter(_mask([SPEED_ZONE]), FilterType.SPEED_FILTER_PERCENT)
    assert (pct.limit_at(2.0, 0.0), pct.limit_at(0.0, 0.0), pct.limit_at(9.0, 0.0)) == (40.0, NO_SPEED_LIMIT, NO_SPEED_LIMIT)
    absolute = SpeedLimitFilter(_mask([SPEED_ZONE]), FilterType.SPEED_FILTER_ABSOLUTE, base=0.0, multiplier=0.005)
    assert absolute.limit_at(2.0, 0.0) == pytest.approx(0.2)
    unknown = SpeedLimitFilter(_mask([(1.0, 3.5, -3.5, 3.5, -1)]), FilterType.SPEED_FILTER_PERCENT)
    with pytest.raises(ValueError, match=r"^speed filter: the mask is unknown \(-1\) at \(2\.00, 0\.00\), which is invalid"):
        unknown.limit_at(2.0, 0.0)
    with pytest.raises(ValueError, match=r"^speed filter: expected CostmapFilterInfo type 1 \(percent\) or 2 \(m/s\), found 0$"):
        SpeedLimitFilter(_mask([]), FilterType.KEEPOUT_FILTER)


def test_rpp_speed_limit_caps_and_lifts() -> None:
    rpp = RegulatedPurePursuit(RppParameters(desired_linear_vel=0.5, use_cost_regulated_linear_velocity_scaling=False))
    rpp.set_plan(np.column_stack([np.linspace(0, 5, 101), np.zeros(101), np.zeros(101)]))
    assert rpp.step((0.0, 0.0, 0.0)).linear == pytest.approx(0.5)
    rpp.set_speed_limit(40.0, True)
    assert rpp.step((0.0, 0.0, 0.0)).linear == pytest.approx(0.2)
    rpp.set_speed_limit(0.3, False)
    assert rpp.step((0.0, 0.0, 0.0)).linear == pytest.approx(0.3)
    rpp.set_speed_limit(0.9, False)  # a limit above the desired speed does not raise it
    assert rpp.step((0.0, 0.0, 0.0)).linear == pytest.approx(0.5)
    rpp.set_speed_limit(NO_SPEED_LIMIT, True)
    assert rpp.step((0.0, 0.0, 0.0)).linear == pytest.approx(0.5)


class _FilterSource(Node):
    """Nav2's costmap_filter_info_server and a mask's map server in one: latched info and masks."""

    def __init__(self) -> None:
        super().__init__("filter_source")
        from aiorobot.msgs.nav2_msgs import CostmapFilterInfo, SpeedLimit
        from aiorobot.msgs.nav_msgs import OccupancyGrid, Odometry
        from aiorobot.nav._map_server import MAP_QOS

        send_map_to_odom(self)
        for name, kind, box in (("keepout", FilterType.KEEPOUT_FILTER, KEEPOUT), ("speed", FilterType.SPEED_FILTER_PERCENT, SPEED_ZONE)):
            self.create_publisher(OccupancyGrid, f"/{name}_mask", MAP_QOS).publish(_mask([box]).to_msg())
            self.create_publisher(CostmapFilterInfo, f"/{name}_filter_info", MAP_QOS).publish(
                CostmapFilterInfo(type=int(kind), filter_mask_topic=f"/{name}_mask", base=0.0, multiplier=1.0))
        self.track: list[tuple[float, float, float]] = []  # ground truth x, y, speed
        self.limits: list[tuple[bool, float]] = []
        self.create_subscription(Odometry, "/ground_truth/odom", self._on_truth, 10)
        self.create_subscription(SpeedLimit, "/speed_limit", lambda m: self.limits.append((bool(m.percentage), float(m.speed_limit))), 10)

    def _on_truth(self, msg: Any) -> None:
        p, v = msg.pose.pose.position, msg.twist.twist.linear
        self.track.append((p.x, p.y, math.hypot(v.x, v.y)))


async def test_navigation_server_routes_around_a_keepout_zone_and_slows_in_a_speed_zone() -> None:
    async with Runtime(use_sim_time=True, handle_signals=False) as rt:
        sim = simulator(seed=4)
        source = rt.add_node(_FilterSource())
        server = rt.add_node(NavigationServer(parameter_overrides={
            "localization_topic": "", "desired_linear_vel": 0.5, "filters": ["keepout_filter", "speed_filter"],
            "keepout_filter.plugin": "nav2_costmap_2d::KeepoutFilter", "keepout_filter.filter_info_topic": "/keepout_filter_info",
            "speed_filter.plugin": "nav2_costmap_2d::SpeedFilter", "speed_filter.filter_info_topic": "/speed_filter_info"}))
        nav = rt.add_node(Navigator())
        rt.add_node(sim)
        assert await nav.go_to_pose(pose_stamped(2.5, 0.0, 0.0))
        async with asyncio.timeout(50):  # wall seconds: generous; the mission ends on sim time
            while not nav.is_task_complete():
                assert sim.time_ns / 1e9 < 40.0, "the goal was not reached in 40 s of sim time"
                await asyncio.sleep(0.02)
    assert nav.get_result().name == "SUCCEEDED" and sim.body.collisions == 0
    track = np.array(source.track)
    assert _gap_to_keepout(track[:, :2]).min() > 0.22 - 0.05  # the robot's body stays out, to a cell
    assert track[:, 1].min() < -1.2
    assert server.last_plan is not None
    # 0.5 m/s outside the zone; inside it (after 0.2 m to slow down) at most 40 % of that
    assert track[track[:, 0] < 0.5, 2].max() > 0.45
    assert track[track[:, 0] > 1.2, 2].max() <= 0.2 + 1e-6
    assert (True, 40.0) in source.limits


async def test_override_lethal_cost_lowers_the_keepout_zone_while_the_robot_stands_in_it() -> None:
    from aiorobot.msgs.nav2_msgs import CostmapFilterInfo
    from aiorobot.msgs.nav_msgs import OccupancyGrid
    from aiorobot.nav._filter_inputs import FilterInputs
    from aiorobot.nav._map_server import MAP_QOS

    class Controller:
        def set_speed_limit(self, limit: float, percentage: bool) -> None:
            self.limit = (limit, percentage)

    async with Runtime(handle_signals=False) as rt:
        node = rt.add_node(Node("costmap", parameter_overrides={
            "filters": ["keepout_filter"], "keepout_filter.plugin": "nav2_costmap_2d::KeepoutFilter",
            "keepout_filter.filter_info_topic": "keepout_costmap_filter_info", "keepout_filter.override_lethal_cost": True,
            "keepout_filter.lethal_override_cost": 200}))
        filters = FilterInputs(node)
        source = rt.add_node(Node("source"))
        source.create_publisher(OccupancyGrid, "keepout_filter_mask", MAP_QOS).publish(_mask([KEEPOUT]).to_msg())
        source.create_publisher(CostmapFilterInfo, "keepout_costmap_filter_info", MAP_QOS).publish(
            CostmapFilterInfo(type=0, filter_mask_topic="keepout_filter_mask", base=0.0, multiplier=1.0))
        cm = _room()
        filters.attach(cm)
        for _ in range(500):
            await rt.settle()
            if filters.keepout is not None:
                break
        controller = Controller()
        assert cm.cost_at(0.0, 0.0) == LETHAL_OBSTACLE
        filters.update(controller, 0.0, 0.5)  # standing in the zone: its cells cost 200, the way out is open
        assert filters.pose_lethal and cm.cost_at(0.0, 0.0) == 200 and controller.limit == (NO_SPEED_LIMIT, False)
        assert plan(cm, (0.0, 0.5), (-2.0, 0.5)).length_m < 2.5
        filters.update(controller, -2.0, 0.5)  # out again: the zone is lethal
        assert not filters.pose_lethal and cm.cost_at(0.0, 0.0) == LETHAL_OBSTACLE
