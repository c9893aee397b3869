"""The collision monitor's core (nav2_collision_monitor's model) and its node's configuration and topics.

The polygon cases restate nav2_collision_monitor's polygons_test / collision_monitor_node_test
in our own numbers: stop, slowdown, limit and approach zones, their order, min_points, invalid sources.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest

from aiorobot import Node, Runtime
from aiorobot.nav import ActionType, CollisionMonitor, CollisionMonitorNode, Zone
from aiorobot.nav._collision_monitor import parse_points

SQUARE = [[0.5, 0.5], [0.5, -0.5], [-0.5, -0.5], [-0.5, 0.5]]


def _zone(name: str, action: ActionType, **kw: object) -> Zone:
    kw.setdefault("vertices", SQUARE)
    kw.setdefault("min_points", 1)
    return Zone(name, action, **kw)  # type: ignore[arg-type]


def test_point_in_polygon_follows_nav2_crossing_rule_for_a_concave_polygon() -> None:
    # an L: the notch (0.25..0.5, 0.25..0.5) is outside
    ell = Zone("l", ActionType.STOP, vertices=[[0, 0], [0.5, 0], [0.5, 0.25], [0.25, 0.25], [0.25, 0.5], [0, 0.5]])
    pts = np.array([[0.1, 0.1], [0.4, 0.1], [0.1, 0.4], [0.4, 0.4], [0.6, 0.1], [-0.01, 0.2]])
    assert ell.inside(pts).tolist() == [True, True, True, False, False, False]


def test_circle_zone_counts_points_strictly_inside_its_radius() -> None:
    c = Zone("c", ActionType.STOP, radius=0.3)
    assert c.inside(np.array([[0.29, 0.0], [0.0, -0.3], [0.3, 0.3]])).tolist() == [True, False, False]


def test_stop_needs_min_points_inside() -> None:
    monitor = CollisionMonitor([_zone("stop", ActionType.STOP, min_points=4)])
    three = np.array([[0.1, 0.0], [0.2, 0.0], [0.3, 0.0], [0.9, 0.0]])
    assert monitor.decide((0.5, 0.0, 0.2), {"scan": three}).action_type == ActionType.DO_NOTHING
    four = np.array([[0.1, 0.0], [0.2, 0.0], [0.3, 0.0], [0.4, 0.0]])
    action = monitor.decide((0.5, 0.0, 0.2), {"scan": four})
    assert (action.action_type, action.polygon_name, action.velocity) == (ActionType.STOP, "stop", (0.0, 0.0, 0.0))


def test_slowdown_scales_and_limit_caps_keeping_the_curvature() -> None:
    pts = {"scan": np.array([[0.1, 0.1]])}
    slow = CollisionMonitor([_zone("slow", ActionType.SLOWDOWN, slowdown_ratio=0.3)]).decide((0.5, 0.1, 0.4), pts)
    assert slow.action_type == ActionType.SLOWDOWN and slow.velocity == pytest.approx((0.15, 0.03, 0.12))
    limit = CollisionMonitor([_zone("lim", ActionType.LIMIT, linear_limit=0.2, angular_limit=1.0)]).decide((0.4, 0.0, 0.8), pts)
    assert limit.action_type == ActionType.LIMIT and limit.velocity == pytest.approx((0.2, 0.0, 0.4))
    turn = CollisionMonitor([_zone("lim", ActionType.LIMIT, linear_limit=1.0, angular_limit=0.2)]).decide((0.4, 0.0, 0.8), pts)
    assert turn.velocity == pytest.approx((0.1, 0.0, 0.2))


def test_approach_scales_by_time_to_collision_over_time_before_collision() -> None:
    # a round footprint of 0.25 m and a point 0.85 m ahead: 0.5 m/s meets it after 12 steps of 0.1 s -> t = 1.2 s
    approach = Zone("approach", ActionType.APPROACH, radius=0.25, min_points=1, time_before_collision=2.0, simulation_time_step=0.1)
    monitor = CollisionMonitor([approach])
    action = monitor.decide((0.5, 0.0, 0.0), {"scan": np.array([[0.85, 0.0]])})
    assert action.action_type == ActionType.APPROACH and action.velocity == pytest.approx((0.3, 0.0, 0.0))
    # driving away, or turning in place next to it: no collision within the horizon
    assert monitor.decide((-0.5, 0.0, 0.0), {"scan": np.array([[0.85, 0.0]])}).action_type == ActionType.DO_NOTHING
    assert monitor.decide((0.0, 0.0, 1.0), {"scan": np.array([[0.3, 0.0]])}).action_type == ActionType.DO_NOTHING


def test_approach_with_a_rectangle_sees_a_collision_from_turning() -> None:
    long_box = Zone("fp", ActionType.APPROACH, vertices=[[0.4, 0.1], [0.4, -0.1], [-0.4, -0.1], [-0.4, 0.1]], min_points=1,
                    time_before_collision=2.0, simulation_time_step=0.1)
    # a point beside the middle of a long base: turning sweeps the front corner into it
    action = CollisionMonitor([long_box]).decide((0.0, 0.0, 1.0), {"scan": np.array([[0.2, 0.3]])})
    assert action.action_type == ActionType.APPROACH and 0.0 < action.velocity[2] < 1.0


def test_stop_wins_and_otherwise_the_slowest_zone_does() -> None:
    pts = {"scan": np.array([[0.1, 0.0]])}
    zones = [_zone("slow", ActionType.SLOWDOWN, slowdown_ratio=0.5), _zone("slower", ActionType.SLOWDOWN, slowdown_ratio=0.2),
             _zone("gentle", ActionType.SLOWDOWN, slowdown_ratio=0.9)]
    action = CollisionMonitor(zones).decide((1.0, 0.0, 0.0), pts)
    assert (action.polygon_name, action.velocity) == ("slower", pytest.approx((0.2, 0.0, 0.0)))
    action = CollisionMonitor([zones[0], _zone("stop", ActionType.STOP)]).decide((1.0, 0.0, 0.0), pts)
    assert (action.action_type, action.polygon_name) == (ActionType.STOP, "stop")


def test_a_source_without_valid_data_stops_the_base_and_zones_read_only_their_sources() -> None:
    monitor = CollisionMonitor([_zone("stop", ActionType.STOP, sources_names=("cloud",))])
    action = monitor.decide((0.5, 0.0, 0.0), {"scan": None, "cloud": np.zeros((0, 2))})
    assert (action.action_type, action.polygon_name, action.velocity) == (ActionType.STOP, "invalid source", (0.0, 0.0, 0.0))
    near = np.array([[0.1, 0.0]])
    assert monitor.decide((0.5, 0.0, 0.0), {"scan": near, "cloud": np.zeros((0, 2))}).action_type == ActionType.DO_NOTHING
    assert monitor.decide((0.5, 0.0, 0.0), {"scan": np.zeros((0, 2)), "cloud": near}).action_type == ActionType.STOP


def test_disabled_zone_is_skipped() -> None:
    monitor = CollisionMonitor([_zone("stop", ActionType.STOP, enabled=False)])
    assert monitor.decide((0.5, 0.0, 0.0), {"scan": np.array([[0.1, 0.0]])}).action_type == ActionType.DO_NOTHING


def test_points_parse_from_nav2_string_or_flat_array_with_clear_errors() -> None:
    assert parse_points("[[0.3, 0.3], [0.3, -0.3], [0.0, 0.0]]", "p").tolist() == [[0.3, 0.3], [0.3, -0.3], [0.0, 0.0]]
    assert parse_points([0.3, 0.3, 0.3, -0.3, 0.0, 0.0], "p").shape == (3, 2)
    with pytest.raises(ValueError, match=r"^PolygonStop\.points: expected at least 3 points, found 2$"):
        parse_points("[[0.3, 0.3], [0.3, -0.3]]", "PolygonStop.points")
    with pytest.raises(ValueError, match=r"^p: expected an even number of values \(x1, y1, x2, y2, \.\.\.\), found 5$"):
        parse_points([0.1, 0.2, 0.3, 0.4, 0.5], "p")
    with pytest.raises(ValueError, match=r"^p: expected a list of \[x, y\] points such as"):
        parse_points("[[0.3, 0.3], oops]", "p")


def _params(**extra: object) -> dict[str, object]:
    params = {"polygons": ["PolygonStop"], "PolygonStop.type": "polygon", "PolygonStop.action_type": "stop",
            "PolygonStop.points": "[[0.4, 0.3], [0.4, -0.3], [0.0, -0.3], [0.0, 0.3]]", "PolygonStop.min_points": 2,
            "observation_sources": ["scan"], "scan.type": "scan", "scan.topic": "scan", **extra}
    return {k: v for k, v in params.items() if v is not None}  # None: leave the parameter out


@pytest.mark.parametrize(("extra", "message"), [
    ({"polygons": []}, r"^collision_monitor: parameter polygons: expected a list of names \(as nav2_collision_monitor\), found none$"),
    ({"observation_sources": None}, r"^collision_monitor: parameter observation_sources: expected a list of names"),
    ({"PolygonStop.action_type": "halt"},
     r"^collision_monitor: parameter PolygonStop\.action_type: expected one of stop, slowdown, limit, approach, none, found 'halt'$"),
    ({"PolygonStop.type": "velocity_polygon"},
     r"^collision_monitor: parameter PolygonStop\.type: expected one of polygon, circle \(velocity_polygon is not implemented\), "
     r"found 'velocity_polygon'$"),
    ({"scan.type": "range"}, r"^collision_monitor: parameter scan\.type: expected one of scan, pointcloud"),
    ({"PolygonStop.sources_names": ["lidar"]},
     r"^collision_monitor: parameter PolygonStop\.sources_names: expected names from observation_sources \['scan'\], found \['lidar'\]$"),
])
def test_bad_configuration_is_one_line_naming_the_parameter(extra: dict[str, object], message: str) -> None:
    with pytest.raises(ValueError, match=message):
        CollisionMonitorNode(parameter_overrides=_params(**extra))


def _settling(rt: Runtime) -> Any:
    """``await until(cond)``: let the runtime settle until ``cond()`` holds (500 rounds at most)."""

    async def until(cond: Callable[[], object]) -> None:
        for _ in range(500):
            await rt.settle()
            if cond():
                return
        raise AssertionError("timed out")

    return until


class _Harness(Node):
    def __init__(self) -> None:
        super().__init__("harness")
        from aiorobot.msgs.geometry_msgs import TransformStamped, Twist
        from aiorobot.msgs.nav2_msgs import CollisionMonitorState
        from aiorobot.msgs.sensor_msgs import LaserScan
        from aiorobot.tf import StaticTransformBroadcaster

        t = TransformStamped()
        t.header.frame_id, t.child_frame_id = "base_footprint", "laser"
        t.transform.translation.x = 0.1  # the laser 0.1 m ahead of the base's centre
        t.transform.rotation.w = 1.0
        StaticTransformBroadcaster(self).send_transform(t)
        self.scan_pub = self.create_publisher(LaserScan, "scan", 5)
        self.cmd_pub = self.create_publisher(Twist, "cmd_vel_smoothed", 10)
        self.out: list[tuple[float, float]] = []
        self.states: list[tuple[int, str]] = []
        self.create_subscription(Twist, "cmd_vel", lambda m: self.out.append((m.linear.x, m.angular.z)), 10)
        self.create_subscription(CollisionMonitorState, "collision_monitor_state",
                                 lambda m: self.states.append((int(m.action_type), str(m.polygon_name))), 10)

    def scan(self, obstacle_at: float) -> None:
        from aiorobot.msgs.sensor_msgs import LaserScan

        ranges = np.full(360, math.inf, dtype=np.float32)
        ranges[175:186] = obstacle_at  # straight ahead of the laser, 11 beams
        msg = LaserScan(angle_min=-math.pi, angle_increment=2 * math.pi / 360, range_min=0.1, range_max=10.0, ranges=ranges)
        msg.header.frame_id = "laser"
        msg.header.stamp = self.now().to_msg()
        self.scan_pub.publish(msg)

    def cmd(self, vx: float) -> None:
        from aiorobot.msgs.geometry_msgs import Twist, Vector3

        self.cmd_pub.publish(Twist(linear=Vector3(x=vx), angular=Vector3(z=0.1)))


async def test_node_forwards_stops_on_a_new_scan_between_commands_and_reports_its_state() -> None:
    async with Runtime(handle_signals=False) as rt:
        node = rt.add_node(CollisionMonitorNode(parameter_overrides=_params(state_topic="collision_monitor_state",
                                                                            base_shift_correction=False)))
        h = rt.add_node(_Harness())
        until = _settling(rt)

        h.cmd(0.5)  # no scan yet: an invalid source stops the base (Nav2: a standing base gets no zero command)
        await until(lambda: h.states)
        assert h.out == [] and h.states == [(1, "invalid source")]
        h.scan(2.0)
        await until(lambda: node.sources[0].points is not None)
        h.cmd(0.5)
        await until(lambda: h.out[-1] == (0.5, 0.1))
        assert h.states[-1] == (0, "")
        h.scan(0.2)  # 0.3 m ahead of the base: inside the stop polygon, no new command needed to act
        await until(lambda: h.out[-1] == (0.0, 0.0))
        assert h.states[-1] == (1, "PolygonStop")
        stats = node.statistics()
        assert stats.sensor_triggered == 1 and stats.action_type == ActionType.STOP and stats.polygon_name == "PolygonStop"


async def test_pointcloud_source_keeps_points_between_min_and_max_height_and_the_toggle_turns_the_monitor_off() -> None:
    from aiorobot.msgs.geometry_msgs import PolygonStamped
    from aiorobot.msgs.nav2_msgs import Toggle
    from aiorobot.msgs.point_cloud2 import create_cloud_xyz32
    from aiorobot.msgs.sensor_msgs import PointCloud2
    from aiorobot.msgs.std_msgs import Header

    params = _params(observation_sources=["cloud"], **{"scan.type": None, "scan.topic": None}, base_shift_correction=False,
                     **{"cloud.type": "pointcloud", "cloud.topic": "points", "cloud.min_height": 0.1, "cloud.max_height": 0.5,
                        "PolygonStop.visualize": True, "PolygonStop.polygon_pub_topic": "polygon_stop"})
    async with Runtime(handle_signals=False) as rt:
        node = rt.add_node(CollisionMonitorNode(parameter_overrides=params))
        h = rt.add_node(_Harness())
        polygons: list[PolygonStamped] = []
        h.create_subscription(PolygonStamped, "polygon_stop", polygons.append, 1)
        cloud_pub = h.create_publisher(PointCloud2, "points", 5)
        toggle = h.create_client(Toggle, "/collision_monitor/toggle")
        until = _settling(rt)

        def cloud(z: float) -> None:
            header = Header(frame_id="laser", stamp=h.now().to_msg())  # 0.1 m ahead of the base
            cloud_pub.publish(create_cloud_xyz32(header, [[0.15, 0.0, z], [0.15, 0.05, z], [0.2, 0.0, z], [0.2, 0.05, z]]))

        cloud(1.0)  # above max_height: an overhang the base passes under
        await until(lambda: node.sources[0].points is not None)
        h.cmd(0.5)
        await until(lambda: h.out and h.out[-1] == (0.5, 0.1))
        cloud(0.2)
        await until(lambda: h.out[-1] == (0.0, 0.0))
        assert node.statistics().polygon_name == "PolygonStop" and polygons and polygons[-1].header.frame_id == "base_footprint"
        assert len(polygons[-1].polygon.points) == 4
        assert await toggle.wait_for_service(timeout_sec=5.0)
        response = await toggle.call_async(Toggle.Request(enable=False))
        assert response.success and response.message == "Collision monitor toggled off successfully"
        h.cmd(0.5)
        await until(lambda: h.out[-1] == (0.5, 0.1))
