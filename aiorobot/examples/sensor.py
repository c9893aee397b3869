"""A timer-driven publisher: a fake IMU that publishes ``sensor_msgs/msg/Imu`` on ``imu``."""

from __future__ import annotations

import math
from typing import Any

from aiorobot import Node, qos_profile_sensor_data
from aiorobot.msgs.sensor_msgs import Imu

__all__ = ["ImuPublisher"]

_GRAVITY_MPS2 = 9.80665


class ImuPublisher(Node):
    """Publishes a slowly yawing, gravity-loaded IMU reading at ``rate_hz``.

    Parameters (ROS parameters, settable from the config): ``rate_hz`` (1-1000),
    ``frame_id``. The header stamp is the runtime clock at publication, which lets
    subscribers measure delivery latency.
    """

    def __init__(self, **kw: Any) -> None:
        super().__init__("imu_sensor", **kw)
        rate_hz = self.declare_parameter(
            "rate_hz", 50.0, description="publication rate", range=(1.0, 1000.0)
        ).value
        self.frame_id = self.declare_parameter(
            "frame_id", "imu_link", description="header.frame_id of the readings"
        ).value
        self.sent = 0
        self.publisher = self.create_publisher(Imu, "imu", qos_profile_sensor_data)
        self.period_sec = 1.0 / rate_hz
        self.timer = self.create_timer(self.period_sec, self.tick)

    async def tick(self) -> None:
        t_sec = self.sent * self.period_sec
        yaw_rate_radps = 0.5 * math.sin(0.5 * t_sec)
        msg = Imu()
        msg.header.frame_id = self.frame_id
        msg.angular_velocity.z = yaw_rate_radps
        msg.linear_acceleration.z = _GRAVITY_MPS2
        msg.header.stamp = self.now().to_msg()
        self.publisher.publish(msg)
        self.sent += 1

    def status_line(self) -> str:
        """One short line for ``aiorobot run``'s live status display."""
        return f"{self.get_name()}: sent {self.sent}"
