"""``CollisionMonitorNode``: nav2_collision_monitor's node over the pure :class:`CollisionMonitor`.

It sits between the controller and the base: every command on ``cmd_vel_in_topic`` is checked
against the latest obstacle points of each source and sent on ``cmd_vel_out_topic`` as it is,
slowed, limited or zeroed; a change of action is logged and published on ``state_topic``
(nav2_msgs/CollisionMonitorState). Parameters keep Nav2's names, defaults and meaning::

    polygons: ["PolygonStop", "FootprintApproach"]
    PolygonStop: {type: polygon, points: "[[0.4, 0.3], [0.4, -0.3], [0.0, -0.3], [0.0, 0.3]]",
                  action_type: stop, min_points: 4}
    FootprintApproach: {type: circle, radius: 0.25, action_type: approach, time_before_collision: 1.2}
    observation_sources: ["scan"]
    scan: {type: scan, topic: scan}

Polygon ``type`` is ``polygon`` (``points`` as Nav2's string ``"[[x, y], ...]"`` or a flat
double array) or ``circle`` (``radius``); source ``type`` is ``scan`` (sensor_msgs/LaserScan) or
``pointcloud`` (sensor_msgs/PointCloud2, kept between ``min_height`` and ``max_height`` in the base
frame). Points are carried into ``base_frame_id`` at check time; with ``base_shift_correction``
through ``odom_frame_id``, so the base's motion since the measurement is taken out (Nav2's); data
newer than the newest odometry by up to ``transform_tolerance`` is taken at that odometry.

Where it differs from Nav2, and why:

- a new scan or cloud also re-checks the last command forwarded; when the new data calls for a
  smaller command, that command goes out at once, not at the controller's next cycle: the monitor
  acts within one sensor period whatever the controller's rate. It only ever lowers what was sent,
  so a silent controller is not kept driving.
- not implemented (an error names them when configured): ``velocity_polygon`` and dynamic
  polygons (``polygon_sub_topic``, ``footprint_topic``), ``range``, ``polygon`` and ``costmap``
  sources, exclusion zones, ``trigger_consecutive_points`` / ``release_consecutive_points``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .._core._node import Node
from .._core._qos import QoSProfile, ReliabilityPolicy
from .._core._warm_up import compile_kernels
from ._collision_monitor import INVALID_SOURCE, ActionType, CollisionAction, CollisionMonitor, Zone, norm2, parse_points

__all__ = ["CollisionMonitorNode", "CollisionMonitorStatistics"]

_SOURCE_TYPES = ("scan", "pointcloud")
_POLYGON_TYPES = ("polygon", "circle")


@dataclass(frozen=True, slots=True)
class CollisionMonitorStatistics:
    """What :meth:`CollisionMonitorNode.statistics` reports (a snapshot)."""

    #: commands received on cmd_vel_in_topic, and commands sent on cmd_vel_out_topic
    commands_in: int
    commands_out: int
    #: commands sent because new sensor data lowered the last one (between controller cycles)
    sensor_triggered: int
    #: the current action and the polygon that causes it ("" for none)
    action_type: ActionType
    polygon_name: str


class _Source:
    """One observation source: the latest points in the sensor's frame, with frame and stamp."""

    def __init__(self, name: str, kind: str, topic: str, timeout: float, min_height: float, max_height: float, enabled: bool) -> None:
        self.name, self.kind, self.topic, self.timeout = name, kind, topic, timeout
        self.min_height, self.max_height, self.enabled = min_height, max_height, enabled
        self.points: NDArray[np.float64] | None = None  # (N, 3) in frame_id
        self.frame_id = ""
        self.stamp: Any = None

    def take_scan(self, scan: Any) -> None:
        ranges = np.asarray(scan.ranges, dtype=np.float64)
        angles = float(scan.angle_min) + np.arange(len(ranges)) * float(scan.angle_increment)
        ok = np.isfinite(ranges) & (ranges >= float(scan.range_min)) & (ranges <= float(scan.range_max))
        r, a = ranges[ok], angles[ok]
        self._take(np.column_stack([r * np.cos(a), r * np.sin(a), np.zeros(len(r))]), scan.header)

    def take_cloud(self, cloud: Any) -> None:
        from aiorobot.msgs.point_cloud2 import read_points_numpy

        xyz = np.asarray(read_points_numpy(cloud, ("x", "y", "z"), skip_nans=True), dtype=np.float64).reshape(-1, 3)
        self._take(xyz[np.isfinite(xyz).all(axis=1)], cloud.header)

    def _take(self, points: NDArray[np.float64], header: Any) -> None:
        self.points, self.frame_id, self.stamp = points, str(header.frame_id), header.stamp


class CollisionMonitorNode(Node):
    """nav2_collision_monitor's node (see the module doc for parameters and differences).

    rclpy difference: it also acts on new sensor data between commands (lowering only), and
    velocity / dynamic polygons and range / polygon / costmap sources are not implemented.
    """

    def __init__(self, node_name: str = "collision_monitor", **kwargs: Any) -> None:
        super().__init__(node_name, **kwargs)
        d = self.declare_parameter
        self.enabled = bool(d("enabled", True).value)
        self.base_frame_id = str(d("base_frame_id", "base_footprint").value)
        self.odom_frame_id = str(d("odom_frame_id", "odom").value)
        cmd_in = str(d("cmd_vel_in_topic", "cmd_vel_smoothed").value)
        cmd_out = str(d("cmd_vel_out_topic", "cmd_vel").value)
        state_topic = str(d("state_topic", "").value)
        self.transform_tolerance = float(d("transform_tolerance", 0.1).value)
        source_timeout = float(d("source_timeout", 2.0).value)
        self.base_shift_correction = bool(d("base_shift_correction", True).value)
        self.stop_pub_timeout = float(d("stop_pub_timeout", 1.0).value)
        source_names = self._names("observation_sources")
        self.sources = [self._source(name, source_timeout) for name in source_names]
        self.monitor = CollisionMonitor([self._zone(name, source_names) for name in self._names("polygons")])

        from aiorobot.msgs.geometry_msgs import PolygonStamped, Twist
        from aiorobot.msgs.nav2_msgs import CollisionMonitorState, Toggle
        from aiorobot.msgs.sensor_msgs import LaserScan, PointCloud2
        from aiorobot.tf import Buffer, TransformListener

        self.buffer = Buffer()
        self.listener = TransformListener(self.buffer, self)
        self.cmd_pub = self.create_publisher(Twist, cmd_out, 10)
        self.state_pub = self.create_publisher(CollisionMonitorState, state_topic, 10) if state_topic else None
        self._polygon_pubs = {z.name: self.create_publisher(PolygonStamped, topic, 1) for z, topic in self._visualized()}
        sensor_qos = QoSProfile(reliability=ReliabilityPolicy.BEST_EFFORT, depth=5)
        for src in self.sources:
            if src.kind == "scan":
                self.create_subscription(LaserScan, src.topic, lambda m, s=src: self._on_data(s, s.take_scan, m), sensor_qos)
            else:
                self.create_subscription(PointCloud2, src.topic, lambda m, s=src: self._on_data(s, s.take_cloud, m), sensor_qos)
        self.create_subscription(Twist, cmd_in, self._on_cmd_vel, 10)
        self.create_service(Toggle, "~/toggle", self._on_toggle)
        self.action = CollisionAction(ActionType.DO_NOTHING, "", (0.0, 0.0, 0.0))
        self._last_in: tuple[float, float, float] | None = None
        self._last_out: tuple[float, float, float] = (0.0, 0.0, 0.0)
        self._stopped_at: Any = None
        self._counts = [0, 0, 0]
        from ._collision_monitor_kernels import warm_up

        compile_kernels(self.get_logger(), warm_up)

    def __repr__(self) -> str:
        return f"<CollisionMonitorNode {self.get_name()} {self.monitor!r} action={self.action.action_type.name}>"

    def statistics(self) -> CollisionMonitorStatistics:
        return CollisionMonitorStatistics(*self._counts, self.action.action_type, self.action.polygon_name)

    # -- configuration -------------------------------------------------------------------

    def _names(self, key: str) -> list[str]:
        from aiorobot import Parameter

        names = list(self.declare_parameter(key, Parameter.Type.STRING_ARRAY).value or [])
        if not names:
            raise ValueError(f"{self.get_name()}: parameter {key}: expected a list of names (as nav2_collision_monitor), found none")
        return names

    def _value(self, key: str, default: Any) -> Any:
        return self.declare_parameter(key, default).value

    def _source(self, name: str, source_timeout: float) -> _Source:
        kind = str(self._value(f"{name}.type", "scan"))
        if kind not in _SOURCE_TYPES:
            raise ValueError(f"{self.get_name()}: parameter {name}.type: expected one of {', '.join(_SOURCE_TYPES)} "
                             f"(range, polygon and costmap sources are not implemented), found {kind!r}")
        return _Source(name, kind, str(self._value(f"{name}.topic", "scan")), float(self._value(f"{name}.source_timeout", source_timeout)),
                       float(self._value(f"{name}.min_height", 0.05)), float(self._value(f"{name}.max_height", 0.5)),
                       bool(self._value(f"{name}.enabled", True)))

    def _zone(self, name: str, source_names: list[str]) -> Zone:
        v = self._value
        where = f"{self.get_name()}: parameter {name}"
        kind = str(v(f"{name}.type", "polygon"))
        if kind not in _POLYGON_TYPES:
            raise ValueError(f"{where}.type: expected one of {', '.join(_POLYGON_TYPES)} (velocity_polygon is not implemented), found {kind!r}")
        action = ActionType.from_parameter(str(v(f"{name}.action_type", "none")), f"{where}.action_type")
        if kind == "polygon":
            points = self.declare_parameter(f"{name}.points").value
            if points is None:
                raise ValueError(f"{where}.points: expected the polygon's points (a footprint_topic or polygon_sub_topic "
                                 f"is not implemented), found none")
            shape: dict[str, Any] = {"vertices": parse_points(points, f"{where}.points")}
        else:
            shape = {"radius": float(v(f"{name}.radius", 0.0))}
        min_points = int(v(f"{name}.min_points", 4))
        if f"{name}.max_points" in self.unclaimed_parameter_overrides():
            min_points = int(v(f"{name}.max_points", 3)) + 1  # deprecated in Nav2, still honoured there
            self.get_logger().warning(f"{name}.max_points is deprecated (as in Nav2): use min_points")
        sources = tuple(str(s) for s in v(f"{name}.sources_names", list(source_names)))
        unknown = [s for s in sources if s not in source_names]
        if unknown:
            raise ValueError(f"{where}.sources_names: expected names from observation_sources {source_names}, found {unknown}")
        try:
            return Zone(name, action, min_points=min_points, slowdown_ratio=float(v(f"{name}.slowdown_ratio", 0.5)),
                        linear_limit=float(v(f"{name}.linear_limit", 0.5)), angular_limit=float(v(f"{name}.angular_limit", 0.5)),
                        time_before_collision=float(v(f"{name}.time_before_collision", 2.0)),
                        simulation_time_step=float(v(f"{name}.simulation_time_step", 0.1)),
                        enabled=bool(v(f"{name}.enabled", True)), sources_names=sources, **shape)
        except ValueError as err:
            raise ValueError(f"{self.get_name()}: {err}") from None

    def _visualized(self) -> list[tuple[Zone, str]]:
        return [(z, str(self._value(f"{z.name}.polygon_pub_topic", z.name))) for z in self.monitor.zones
                if bool(self._value(f"{z.name}.visualize", False))]

    # -- inputs --------------------------------------------------------------------------

    def _on_toggle(self, request: Any, response: Any) -> Any:
        self.enabled = bool(request.enable)
        response.success = True
        response.message = f"Collision monitor toggled {'on' if self.enabled else 'off'} successfully"
        return response

    def _on_cmd_vel(self, msg: Any) -> None:
        v = (float(msg.linear.x), float(msg.linear.y), float(msg.angular.z))
        if not all(math.isfinite(c) for c in v):
            self.get_logger().error("Velocity message contains NaNs or Infs! Ignoring as invalid!", throttle_duration_sec=1.0)
            return
        self._counts[0] += 1
        self._last_in = v
        self._process(v)

    def _on_data(self, source: _Source, take: Any, msg: Any) -> None:
        take(msg)
        # act within one sensor period: lower what went out last if this data calls for it
        if self._last_in is None or self._last_out == (0.0, 0.0, 0.0):
            return
        action = self._decide(self._last_in)
        if norm2(action.velocity) < norm2(self._last_out):
            self._counts[2] += 1
            self._apply(action)

    # -- the check -----------------------------------------------------------------------

    def _process(self, velocity: tuple[float, float, float]) -> None:
        self._apply(self._decide(velocity))

    def _decide(self, velocity: tuple[float, float, float]) -> CollisionAction:
        if not self.enabled:
            return CollisionAction(ActionType.DO_NOTHING, "", velocity)
        return self.monitor.decide(velocity, {s.name: self._points(s) for s in self.sources if s.enabled})

    def _apply(self, action: CollisionAction) -> None:
        if action.polygon_name != self.action.polygon_name:
            self._notify(action)
        self.action = action
        self._publish(action.velocity)
        for zone in self.monitor.zones:
            if zone.name in self._polygon_pubs:
                self._polygon_pubs[zone.name].publish(self._polygon_msg(zone))

    def _points(self, source: _Source) -> NDArray[np.float64] | None:
        """The source's points (N, 2) in the base frame now; None when it has no valid data (Nav2
        then stops the base) unless its ``source_timeout`` is 0."""
        from aiorobot import Duration, Time
        from aiorobot.tf import TransformException, transform_from_pq

        invalid = None if source.timeout != 0.0 else np.zeros((0, 2))
        if source.points is None:
            return invalid
        stamp = Time.from_msg(source.stamp)
        if source.timeout > 0.0 and (self.now() - stamp).nanoseconds > Duration(seconds=source.timeout).nanoseconds:
            return invalid
        try:
            if self.base_shift_correction:
                t = self.buffer.lookup_transform_full(self.base_frame_id, Time(), source.frame_id, self._odom_time(stamp),
                                                      self.odom_frame_id)
            else:
                t = self.buffer.lookup_transform(self.base_frame_id, source.frame_id, Time())
        except TransformException as err:
            self.get_logger().warning(f"source {source.name}: no transform {source.frame_id} -> {self.base_frame_id} ({err})",
                                      throttle_duration_sec=2.0)
            return invalid
        tr, q = t.transform.translation, t.transform.rotation
        m = transform_from_pq((tr.x, tr.y, tr.z), (q.x, q.y, q.z, q.w))  # tf's (x, y, z, w) order
        pts = source.points @ m[:3, :3].T + m[:3, 3]
        if source.kind == "pointcloud":
            pts = pts[(pts[:, 2] >= source.min_height) & (pts[:, 2] <= source.max_height)]
        return np.ascontiguousarray(pts[:, :2])

    def _odom_time(self, stamp: Any) -> Any:
        """The time to take the sensor's pose in odom at: its stamp, or the newest odometry when the data is
        newer than that by at most ``transform_tolerance`` (a scan stamped before the odometry of its instant arrives)."""
        from aiorobot import Duration, Time

        newest = Time.from_msg(self.buffer.lookup_transform(self.odom_frame_id, self.base_frame_id, Time()).header.stamp)
        if newest < stamp and (stamp - newest).nanoseconds <= Duration(seconds=self.transform_tolerance).nanoseconds:
            return newest
        return stamp

    # -- outputs -------------------------------------------------------------------------

    def _notify(self, action: CollisionAction) -> None:
        log = self.get_logger()
        zone = next((z for z in self.monitor.zones if z.name == action.polygon_name), None)
        if action.action_type == ActionType.STOP:
            if action.polygon_name == INVALID_SOURCE:
                log.warning("Robot to stop due to invalid source. Either due to data not published yet, or to lack of new data "
                            "received within the sensor timeout, or if impossible to transform data to base frame")
            else:
                log.info(f"Robot to stop due to {action.polygon_name} polygon")
        elif action.action_type == ActionType.SLOWDOWN and zone is not None:
            log.info(f"Robot to slowdown for {zone.slowdown_ratio * 100:f} percents due to {zone.name} polygon")
        elif action.action_type == ActionType.LIMIT:
            log.info(f"Robot to limit speed due to {action.polygon_name} polygon")
        elif action.action_type == ActionType.APPROACH and zone is not None:
            log.info(f"Robot to approach for {zone.time_before_collision:f} seconds away from collision")
        else:
            log.info("Robot to continue normal operation")
        if self.state_pub is not None:
            from aiorobot.msgs.nav2_msgs import CollisionMonitorState

            self.state_pub.publish(CollisionMonitorState(action_type=int(action.action_type), polygon_name=action.polygon_name))

    def _publish(self, v: tuple[float, float, float]) -> None:
        """Nav2's publishVelocity: a zero command is repeated for ``stop_pub_timeout`` after the stop, then no more."""
        from aiorobot import Duration
        from aiorobot.msgs.geometry_msgs import Twist, Vector3

        if v == (0.0, 0.0, 0.0):
            if self._last_out != (0.0, 0.0, 0.0):
                self._stopped_at = self.now()  # the base just stopped
            elif self._stopped_at is None or (self.now() - self._stopped_at).nanoseconds > Duration(seconds=self.stop_pub_timeout).nanoseconds:
                return
        self._last_out = v
        self._counts[1] += 1
        self.cmd_pub.publish(Twist(linear=Vector3(x=v[0], y=v[1]), angular=Vector3(z=v[2])))

    def _polygon_msg(self, zone: Zone) -> Any:
        from aiorobot.msgs.geometry_msgs import Point32, Polygon, PolygonStamped

        if len(zone.vertices):
            xy = zone.vertices
        else:  # Nav2's circleToPolygon: 16 edges
            a = np.arange(16) * (2 * math.pi / 16)
            xy = np.column_stack([zone.radius * np.cos(a), zone.radius * np.sin(a)])
        msg = PolygonStamped(polygon=Polygon(points=[Point32(x=float(x), y=float(y)) for x, y in xy]))
        msg.header.frame_id = self.base_frame_id
        msg.header.stamp = self.now().to_msg()
        return msg
