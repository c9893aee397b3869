"""``ComplementaryFilter``: the complementary estimator on ``/imu/data`` + ``/odom``, publishing ``/imu/fused``."""

from __future__ import annotations

import math
from typing import Any

from aiorobot import Node
from aiorobot.tf import quaternion_from_euler

from ._complementary import ComplementaryEstimator

__all__ = ["ComplementaryFilter"]


class ComplementaryFilter(Node):
    """Gyro integrated and blended with accelerometer roll/pitch and odometry yaw by ``alpha``.

    Subscribes ``/imu/data`` (sensor_msgs/Imu) and ``/odom`` (nav_msgs/Odometry); publishes
    ``/imu/fused`` (the IMU message with the fused orientation, stamped with the IMU's header) and,
    with ``publish_tf``, the ``odom_frame -> base_link_frame`` rotation.

    Parameters: ``alpha`` (0.98), ``publish_tf`` (false), ``odom_frame`` ("odom"),
    ``base_link_frame`` ("base_link"), ``imu_topic``, ``odom_topic``, ``fused_topic``.
    """

    def __init__(self, name: str = "complementary_filter", **kw: Any) -> None:
        super().__init__(name, **kw)
        d = self.declare_parameter
        alpha = d("alpha", 0.98, description="gyro weight", range=(0.0, 1.0)).value
        self.publish_tf = bool(d("publish_tf", False).value)
        self.odom_frame = d("odom_frame", "odom").value
        self.base_link_frame = d("base_link_frame", "base_link").value
        imu_topic = d("imu_topic", "/imu/data").value
        odom_topic = d("odom_topic", "/odom").value
        fused_topic = d("fused_topic", "/imu/fused").value
        self.estimator = ComplementaryEstimator(alpha)
        from aiorobot.msgs.nav_msgs import Odometry
        from aiorobot.msgs.sensor_msgs import Imu

        self.fused_pub = self.create_publisher(Imu, fused_topic, 10)
        self.create_subscription(Imu, imu_topic, self.on_imu, 50)
        self.create_subscription(Odometry, odom_topic, self.on_odom, 10)
        self._tf = None
        if self.publish_tf:
            from aiorobot.tf import TransformBroadcaster

            self._tf = TransformBroadcaster(self)

    def on_odom(self, msg: Any) -> None:
        q = msg.pose.pose.orientation
        self.estimator.set_odometry_yaw(math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z)))

    def on_imu(self, msg: Any) -> None:
        w, a = msg.angular_velocity, msg.linear_acceleration
        stamp = msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9
        before = self.estimator.rejected
        roll, pitch, yaw = self.estimator.step(stamp, w.x, w.y, w.z, a.x, a.y, a.z)
        if self.estimator.rejected != before:
            self.get_logger().warning("/imu/data: skipped a sample with NaN or inf", throttle_duration_sec=5.0)
            return
        q = quaternion_from_euler(roll, pitch, yaw)
        msg.orientation.x, msg.orientation.y, msg.orientation.z, msg.orientation.w = q
        self.fused_pub.publish(msg)
        if self._tf is not None:
            from aiorobot.msgs.geometry_msgs import TransformStamped

            t = TransformStamped()
            t.header.stamp = msg.header.stamp
            t.header.frame_id, t.child_frame_id = self.odom_frame, self.base_link_frame
            t.transform.rotation.x, t.transform.rotation.y, t.transform.rotation.z, t.transform.rotation.w = q
            self._tf.send_transform(t)
