"""``SlamNode``: slam_toolbox's interface on top of :class:`~aiorobot.nav._slam.Slam`.

Subscribes ``scan_topic``; reads ``odom_frame -> base_frame`` at each scan's stamp from tf (a scan
waits up to ``transform_timeout`` for it, as slam_toolbox's tf MessageFilter makes it) and
``base_frame -> <laser>`` (static); publishes ``/map`` (transient local) every
``map_update_interval`` s when it changed, ``map_frame -> odom_frame`` on ``/tf`` every
``transform_publish_period`` s (0: never) post-dated by ``transform_timeout``, ``pose``
(PoseWithCovarianceStamped) at each new node, and ``/diagnostics`` once a second: counts of the
input it refused (non-finite beams, empty scans, scans without a transform, odometry jumps) and
of loop closures. Services, slam_toolbox's names and types: ``slam_toolbox/save_map``
(SaveMap: ``<name>.yaml`` + ``.pgm`` as map_saver writes them), ``slam_toolbox/serialize_map``
(SerializePoseGraph: ``<filename>.posegraph``) and ``slam_toolbox/deserialize_map``
(DeserializePoseGraph: continue mapping at the first node or a given pose, or localise at a pose).

Differences from slam_toolbox, and why: ``map_start_pose`` also places a fresh map (the first
node), so a simulator's world frame can be the map frame; the ``.posegraph`` file is an
``.npz`` archive (slam_toolbox's is a boost archive of Karto's classes, which nothing here can
read), and there is no ``.data`` file beside it.
"""

from __future__ import annotations

import math
from dataclasses import fields
from typing import Any

import numpy as np

from .._core._node import Node
from .._core._qos import QoSProfile, ReliabilityPolicy
from .._core._warm_up import compile_kernels
from ._geometry import transform_to_xyyaw, yaw_quaternion
from ._map_server import MAP_QOS
from ._slam import Slam, SlamParameters

__all__ = ["SlamNode"]

#: SlamParameters fields a node parameter sets under the same name
_CORE = tuple(f.name for f in fields(SlamParameters))


class SlamNode(Node):
    """Online 2D lidar SLAM. Parameters: every :class:`~aiorobot.nav._slam.SlamParameters` field
    (slam_toolbox's names: ``mode``, ``resolution``, ``max_laser_range``, ``minimum_travel_distance``,
    ``minimum_travel_heading``, ``do_loop_closing``, ``loop_search_maximum_distance``, ...) and
    ``odom_frame`` (odom), ``map_frame`` (map), ``base_frame`` (base_link), ``scan_topic`` (/scan),
    ``map_update_interval`` (5.0 s), ``transform_publish_period`` (0.05 s), ``transform_timeout``
    (0.2 s), ``map_file_name`` (a .posegraph to start from) and ``map_start_pose`` ([x, y, yaw]).

    rclpy difference: slam_toolbox's interface with other defaults, another graph file format and
    ``map_start_pose`` placing a fresh map too; see docs/rclpy-differences.md.
    """

    def __init__(self, node_name: str = "slam_toolbox", **kwargs: Any) -> None:
        super().__init__(node_name, **kwargs)
        d = self.declare_parameter
        defaults = SlamParameters()
        values = {name: d(name, getattr(defaults, name)).value for name in _CORE}
        self.params = SlamParameters(**values)
        self.odom_frame = str(d("odom_frame", "odom").value)
        self.map_frame = str(d("map_frame", "map").value)
        self.base_frame = str(d("base_frame", "base_link").value)
        scan_topic = str(d("scan_topic", "/scan").value)
        self.map_update_interval = float(d("map_update_interval", 5.0).value)
        self.transform_publish_period = float(d("transform_publish_period", 0.05).value)
        self.transform_timeout = float(d("transform_timeout", 0.2).value)
        map_file = str(d("map_file_name", "").value)
        start = d("map_start_pose", [0.0, 0.0, 0.0]).value
        if len(start) != 3 or not all(math.isfinite(float(v)) for v in start):
            raise ValueError(f"map_start_pose: expected [x, y, yaw] (3 finite numbers), found {list(start)!r}")
        start_pose = (float(start[0]), float(start[1]), float(start[2]))
        if map_file:
            self.slam = Slam.load(map_file, self.params)
            self.slam.continue_from(start_pose)
            self.get_logger().info(f"continuing {map_file} ({len(self.slam.graph)} nodes) at {start_pose}")
        else:
            self.slam = Slam(self.params, start_pose=start_pose)
        #: scans refused before they reached the core: no transform for their stamp or frame
        self.scans_without_transform = 0
        self._last_stamp: Any = None
        self._published_version = -1

        from aiorobot.msgs.diagnostic_msgs import DiagnosticArray
        from aiorobot.msgs.geometry_msgs import PoseWithCovarianceStamped
        from aiorobot.msgs.nav_msgs import OccupancyGrid
        from aiorobot.msgs.sensor_msgs import LaserScan
        from aiorobot.msgs.slam_toolbox import DeserializePoseGraph, SaveMap, SerializePoseGraph
        from aiorobot.tf import Buffer, TransformBroadcaster, TransformListener

        from .._core._groups import MutuallyExclusiveCallbackGroup

        self.buffer = Buffer()
        self.listener = TransformListener(self.buffer, self)
        self.broadcaster = TransformBroadcaster(self)
        # its own group: a scan waiting for its transform must not hold up the tf listener's callbacks
        self.create_subscription(LaserScan, scan_topic, self._on_scan, QoSProfile(reliability=ReliabilityPolicy.BEST_EFFORT, depth=5),
                                 callback_group=MutuallyExclusiveCallbackGroup())
        self.map_pub = self.create_publisher(OccupancyGrid, "/map", MAP_QOS)
        self.pose_pub = self.create_publisher(PoseWithCovarianceStamped, "pose", 10)
        self.diag_pub = self.create_publisher(DiagnosticArray, "/diagnostics", 10)
        self.create_service(SaveMap, "slam_toolbox/save_map", self._save_map)
        self.create_service(SerializePoseGraph, "slam_toolbox/serialize_map", self._serialize)
        self.create_service(DeserializePoseGraph, "slam_toolbox/deserialize_map", self._deserialize)
        if self.map_update_interval > 0:
            self.create_timer(self.map_update_interval, self.publish_map)
        if self.transform_publish_period > 0:
            self.create_timer(self.transform_publish_period, self._send_tf)
        self.create_timer(1.0, self.publish_diagnostics)
        from ._kernels import warm_up as nav_warm_up
        from ._slam_kernels import warm_up

        def _warm() -> None:
            warm_up()
            nav_warm_up("integrate_scan")

        compile_kernels(self.get_logger(), _warm)  # not at the first scan

    def __repr__(self) -> str:
        return f"<SlamNode {self.get_name()} {self.slam!r}>"

    # -- input ---------------------------------------------------------------------------

    async def _on_scan(self, scan: Any) -> None:
        from aiorobot import Time
        from aiorobot.tf import TransformException

        stamp = Time.from_msg(scan.header.stamp)
        try:
            if not self.buffer.can_transform(self.odom_frame, self.base_frame, stamp):
                await self.buffer.wait_for_transform(self.odom_frame, self.base_frame, stamp, timeout_sec=self.transform_timeout)
            odom = transform_to_xyyaw(self.buffer.lookup_transform(self.odom_frame, self.base_frame, stamp))
            laser = transform_to_xyyaw(self.buffer.lookup_transform(self.base_frame, scan.header.frame_id, Time()))
        except TransformException as err:
            self.scans_without_transform += 1
            self.get_logger().warning(f"slam: scan in frame {scan.header.frame_id!r} at {stamp.nanoseconds} ns ignored: "
                                      f"no transform to {self.odom_frame!r} ({err})", throttle_duration_sec=2.0)
            return
        update = self.slam.add_scan(odom, np.asarray(scan.ranges, dtype=np.float64), float(scan.angle_min),
                                    float(scan.angle_increment), float(scan.range_min), float(scan.range_max),
                                    laser_pose=laser, stamp_sec=stamp.nanoseconds * 1e-9)
        if update.skipped:
            self.get_logger().warning(f"slam: scan at {stamp.nanoseconds} ns ignored ({update.skipped.replace('_', ' ')})",
                                      throttle_duration_sec=2.0)
            return
        self._last_stamp = scan.header.stamp
        if update.node >= 0:
            self._publish_pose(scan.header.stamp)
        if update.loop_closed:
            self.get_logger().info(f"slam: loop closed at node {update.node} ({self.slam.statistics().loop_closures} so far)")

    # -- outputs -------------------------------------------------------------------------

    def _send_tf(self) -> None:
        if self._last_stamp is None:
            return
        from aiorobot import Duration, Time
        from aiorobot.msgs.geometry_msgs import TransformStamped

        x, y, yaw = self.slam.map_to_odom
        t = TransformStamped()
        t.header.frame_id = self.map_frame
        t.child_frame_id = self.odom_frame
        t.header.stamp = (Time.from_msg(self._last_stamp) + Duration(seconds=self.transform_timeout)).to_msg()
        t.transform.translation.x, t.transform.translation.y = x, y
        t.transform.rotation = yaw_quaternion(yaw)
        self.broadcaster.send_transform(t)

    def _publish_pose(self, stamp: Any) -> None:
        from aiorobot.msgs.geometry_msgs import PoseWithCovarianceStamped

        x, y, yaw = self.slam.pose
        msg = PoseWithCovarianceStamped()
        msg.header.frame_id = self.map_frame
        msg.header.stamp = stamp
        msg.pose.pose.position.x, msg.pose.pose.position.y = x, y
        msg.pose.pose.orientation = yaw_quaternion(yaw)
        self.pose_pub.publish(msg)

    def publish_map(self) -> None:
        """Publish ``/map`` if the map changed since the last time."""
        if not len(self.slam.graph) or self.slam.map_version == self._published_version:
            return
        self._published_version = self.slam.map_version
        self.map_pub.publish(self.slam.occupancy_map(self.map_frame).to_msg(self.now().to_msg()))

    def publish_diagnostics(self) -> None:
        from aiorobot.msgs.diagnostic_msgs import DiagnosticArray, DiagnosticStatus, KeyValue

        s = self.slam.statistics()
        refused = {"beams_invalid": s.beams_invalid, "scans_empty": s.scans_empty,
                   "scans_without_transform": self.scans_without_transform, "odometry_jumps": s.odometry_jumps}
        counts = {"scans": s.scans, "nodes": s.nodes, "loop_closures": s.loop_closures, "recovery_searches": s.recovery_searches,
                  "loop_closures_rejected": s.loop_closures_rejected, "matches_failed": s.matches_failed,
                  "beams_out_of_range": s.beams_out_of_range, **refused}
        bad = {k: v for k, v in refused.items() if v}
        status = DiagnosticStatus(level=DiagnosticStatus.WARN if bad else DiagnosticStatus.OK, name=f"{self.get_name()}: slam",
                                  message=("ignored input: " + ", ".join(f"{v} {k.replace('_', ' ')}" for k, v in bad.items()))
                                  if bad else f"{s.nodes} nodes, {s.loop_closures} loop closures",
                                  hardware_id=self.base_frame,
                                  values=[KeyValue(key=k, value=str(v)) for k, v in counts.items()])
        msg = DiagnosticArray(status=[status])
        msg.header.stamp = self.now().to_msg()
        self.diag_pub.publish(msg)

    # -- services ------------------------------------------------------------------------

    def _save_map(self, request: Any, response: Any) -> Any:
        from ._maps import save_map

        if not len(self.slam.graph):
            self.get_logger().warning("slam: cannot save the map: no scan has made a node yet")
            response.result = response.RESULT_NO_MAP_RECEIEVD
            return response
        name = request.name.data or "map"
        try:
            path = save_map(self.slam.occupancy_map(self.map_frame), name)
        except OSError as err:
            self.get_logger().error(f"slam: cannot save the map as {name!r}: {err}")
            response.result = response.RESULT_UNDEFINED_FAILURE
            return response
        self.get_logger().info(f"slam: map saved to {path}")
        response.result = response.RESULT_SUCCESS
        return response

    def _serialize(self, request: Any, response: Any) -> Any:
        try:
            path = self.slam.save(request.filename)
        except OSError as err:
            self.get_logger().error(f"slam: cannot write the pose graph to {request.filename!r}: {err}")
            response.result = response.RESULT_FAILED_TO_WRITE_FILE
            return response
        self.get_logger().info(f"slam: pose graph ({len(self.slam.graph)} nodes) written to {path}")
        response.result = response.RESULT_SUCCESS
        return response

    def _deserialize(self, request: Any, response: Any) -> Any:
        kinds = {1: "START_AT_FIRST_NODE", 2: "START_AT_GIVEN_POSE", 3: "LOCALIZE_AT_POSE"}
        if request.match_type not in kinds:
            raise ValueError(f"deserialize_map: expected match_type 1 (START_AT_FIRST_NODE), 2 (START_AT_GIVEN_POSE) "
                             f"or 3 (LOCALIZE_AT_POSE), found {request.match_type}")
        params = SlamParameters(**{**{f: getattr(self.params, f) for f in _CORE},
                                   "mode": "localization" if request.match_type == 3 else "mapping"})
        slam = Slam.load(request.filename, params)  # ValueError (a bad file) reaches the caller as the service's error
        p = request.initial_pose
        pose = tuple(slam.graph.poses[0]) if request.match_type == 1 else (float(p.x), float(p.y), float(p.theta))
        slam.continue_from(pose)  # type: ignore[arg-type]
        self.slam = slam
        self._published_version = -1
        self.get_logger().info(f"slam: {request.filename} loaded ({len(slam.graph)} nodes), {kinds[request.match_type]} "
                               f"at ({pose[0]:.2f}, {pose[1]:.2f}, {pose[2]:.2f}), mode {params.mode}")
        return response
