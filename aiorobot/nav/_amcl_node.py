"""``AmclNode``: nav2_amcl's interface on top of :class:`~aiorobot.nav.Amcl`.

Subscribes ``/map`` (transient local), ``/scan`` and ``/initialpose``; reads odom -> base_link
and base_link -> laser from tf; publishes ``amcl_pose`` (PoseWithCovarianceStamped) and the
map -> odom transform (so map -> base_link is AMCL's estimate), post-dated by
``transform_tolerance`` as nav2_amcl does.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .._core._node import Node
from .._core._warm_up import compile_kernels
from .._core._qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from ._amcl import Amcl, AmclParameters
from ._geometry import transform_to_xyyaw, xyyaw, yaw_quaternion
from ._map_server import MAP_QOS
from ._maps import OccupancyMap

__all__ = ["AmclNode"]

_PARAMS = ("min_particles", "max_particles", "pf_err", "pf_z", "alpha1", "alpha2", "alpha3", "alpha4", "alpha5",
           "robot_model_type", "z_hit", "z_rand", "sigma_hit", "laser_likelihood_max_dist", "laser_min_range",
           "laser_max_range", "max_beams", "update_min_d", "update_min_a", "resample_interval",
           "recovery_alpha_slow", "recovery_alpha_fast")


class AmclNode(Node):
    """Parameters: nav2_amcl's (see :class:`AmclParameters`) plus ``global_frame_id`` (map),
    ``odom_frame_id`` (odom), ``base_frame_id`` (base_link), ``scan_topic`` (scan),
    ``set_initial_pose`` / ``initial_pose`` ({x, y, yaw}), ``transform_tolerance`` (1.0 s), ``seed``."""

    def __init__(self, node_name: str = "amcl", **kwargs: Any) -> None:
        super().__init__(node_name, **kwargs)
        defaults = AmclParameters()
        values = {name: self.declare_parameter(name, getattr(defaults, name)).value for name in _PARAMS}
        self.params = AmclParameters(**values)
        self.global_frame = str(self.declare_parameter("global_frame_id", "map").value)
        self.odom_frame = str(self.declare_parameter("odom_frame_id", "odom").value)
        self.base_frame = str(self.declare_parameter("base_frame_id", "base_link").value)
        self.tolerance = float(self.declare_parameter("transform_tolerance", 1.0).value)
        self.seed = int(self.declare_parameter("seed", 0).value)
        self._initial: tuple[float, float, float] | None = None
        if bool(self.declare_parameter("set_initial_pose", False).value):
            self._initial = (float(self.declare_parameter("initial_pose.x", 0.0).value),
                             float(self.declare_parameter("initial_pose.y", 0.0).value),
                             float(self.declare_parameter("initial_pose.yaw", 0.0).value))
        scan_topic = str(self.declare_parameter("scan_topic", "scan").value)
        from aiorobot.msgs.geometry_msgs import PoseWithCovarianceStamped
        from aiorobot.msgs.nav_msgs import OccupancyGrid
        from aiorobot.msgs.sensor_msgs import LaserScan
        from aiorobot.tf import Buffer, TransformBroadcaster, TransformListener

        self.buffer = Buffer()
        self.listener = TransformListener(self.buffer, self)
        self.broadcaster = TransformBroadcaster(self)
        self.filter: Amcl | None = None
        self.updates = 0
        self.create_subscription(OccupancyGrid, "/map", self._on_map, MAP_QOS)
        from .._core._groups import MutuallyExclusiveCallbackGroup

        # Its own group: a scan waiting for its transform must not hold up the tf listener's callbacks.
        self.create_subscription(LaserScan, scan_topic if scan_topic.startswith("/") else f"/{scan_topic}", self._on_scan,
                                 QoSProfile(reliability=ReliabilityPolicy.BEST_EFFORT, depth=5),
                                 callback_group=MutuallyExclusiveCallbackGroup())
        self.create_subscription(PoseWithCovarianceStamped, "/initialpose", self._on_initial_pose, 10)
        self.pose_pub = self.create_publisher(PoseWithCovarianceStamped, "amcl_pose",
                                              QoSProfile(durability=DurabilityPolicy.TRANSIENT_LOCAL, depth=1))
        self._map_to_odom: tuple[float, float, float] | None = None
        from ._kernels import warm_up

        compile_kernels(self.get_logger(), lambda: warm_up("likelihood_weights"))  # not at the first scan

    # -- inputs -------------------------------------------------------------------------

    def _on_map(self, msg: Any) -> None:
        grid = OccupancyMap.from_msg(msg)
        self.filter = Amcl(grid.occupied, grid.resolution, grid.origin[:2], self.params, seed=self.seed)
        if self._initial is not None:
            self.filter.set_initial_pose(*self._initial)
        self.get_logger().info(f"map received ({grid.width}x{grid.height}); {'initial pose set' if self._initial else 'waiting for /initialpose'}")

    def _on_initial_pose(self, msg: Any) -> None:
        x, y, yaw = xyyaw(msg.pose)
        cov = msg.pose.covariance
        self._initial = (x, y, yaw)
        if self.filter is not None:
            self.filter.set_initial_pose(x, y, yaw, cov_xx=max(float(cov[0]), 1e-4), cov_yy=max(float(cov[7]), 1e-4),
                                         cov_aa=max(float(cov[35]), 1e-4))
            self.get_logger().info(f"initial pose ({x:.2f}, {y:.2f}, {yaw:.2f})")

    async def _on_scan(self, scan: Any) -> None:
        from aiorobot import Time
        from aiorobot.tf import TransformException

        amcl = self.filter
        if amcl is None or not amcl.initialized:
            return
        ranges = np.asarray(scan.ranges, dtype=np.float64)
        stamp = Time.from_msg(scan.header.stamp)
        try:
            # As nav2_amcl's tf MessageFilter: a scan waits (up to transform_tolerance) for the
            # odom -> base_link at its stamp, which an odometry filter may publish a moment later.
            if not self.buffer.can_transform(self.odom_frame, self.base_frame, stamp):
                await self.buffer.wait_for_transform(self.odom_frame, self.base_frame, stamp, timeout_sec=self.tolerance)
            odom = transform_to_xyyaw(self.buffer.lookup_transform(self.odom_frame, self.base_frame, stamp))
            laser = transform_to_xyyaw(self.buffer.lookup_transform(self.base_frame, scan.header.frame_id, Time()))
        except TransformException as err:
            self.get_logger().warning(f"amcl: no transform for the scan at {stamp.nanoseconds} ns ({err})", throttle_duration_sec=2.0)
            return
        if amcl.update(odom, ranges, float(scan.angle_min), float(scan.angle_increment), range_min=float(scan.range_min),
                       range_max=float(scan.range_max), laser_pose=laser, force=self.updates == 0 and amcl._last_odom is not None):
            self.updates += 1
            self._publish(odom, scan.header.stamp)
        elif self._map_to_odom is not None:
            self._send_tf(scan.header.stamp)

    # -- outputs ------------------------------------------------------------------------

    def _publish(self, odom: tuple[float, float, float], stamp: Any) -> None:
        from aiorobot.msgs.geometry_msgs import PoseWithCovarianceStamped

        assert self.filter is not None
        x, y, yaw = self.filter.pose
        cov = self.filter.covariance
        msg = PoseWithCovarianceStamped()
        msg.header.frame_id = self.global_frame
        msg.header.stamp = stamp
        msg.pose.pose.position.x, msg.pose.pose.position.y = x, y
        msg.pose.pose.orientation = yaw_quaternion(yaw)
        c = np.zeros(36)
        c[0], c[1], c[6], c[7] = cov[0, 0], cov[0, 1], cov[1, 0], cov[1, 1]
        c[35] = cov[2, 2]
        msg.pose.covariance = c
        self.pose_pub.publish(msg)
        # map -> odom = map -> base * (odom -> base)^-1
        ox, oy, oyaw = odom
        myaw = yaw - oyaw
        mx = x - (math.cos(myaw) * ox - math.sin(myaw) * oy)
        my = y - (math.sin(myaw) * ox + math.cos(myaw) * oy)
        self._map_to_odom = (mx, my, myaw)
        self._send_tf(stamp)

    def _send_tf(self, stamp: Any) -> None:
        from aiorobot import Duration, Time
        from aiorobot.msgs.geometry_msgs import TransformStamped

        assert self._map_to_odom is not None
        mx, my, myaw = self._map_to_odom
        t = TransformStamped()
        t.header.frame_id = self.global_frame
        t.child_frame_id = self.odom_frame
        t.header.stamp = (Time.from_msg(stamp) + Duration(seconds=self.tolerance)).to_msg()
        t.transform.translation.x, t.transform.translation.y = mx, my
        t.transform.rotation = yaw_quaternion(myaw)
        self.broadcaster.send_transform(t)
