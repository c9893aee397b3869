"""A subscriber on the priority loop that keeps statistics of the IMU stream.

The figures come from :class:`~aiorobot.examples.stats.TopicStatistics` (the pure core);
this node only feeds it from a subscription and formats it for ``aiorobot run``.
"""

from __future__ import annotations

from typing import Any

from aiorobot import Node, qos_profile_sensor_data
from aiorobot.msgs.sensor_msgs import Imu

from .stats import TopicStatistics

__all__ = ["RateMonitor"]


class RateMonitor(Node):
    """Subscribes to ``imu_in`` (remap it) and measures rate and latency from ``header.stamp``.

    Runs well on the priority loop (``executor = "priority"``): latency then includes the
    hand-over between loops.
    """

    def __init__(self, **kw: Any) -> None:
        super().__init__("imu_monitor", **kw)
        window_sec = self.declare_parameter(
            "window_sec", 1.0, description="rate window", range=(0.1, 60.0)
        ).value
        self.stats = TopicStatistics(window_sec=window_sec)
        self.subscription = self.create_subscription(
            Imu, "imu_in", self.on_imu, qos_profile_sensor_data
        )

    async def on_imu(self, msg: Imu) -> None:
        now_ns = self.now().nanoseconds
        stamp_ns = msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec
        self.stats.record(now_ns, now_ns - stamp_ns)

    def status_line(self) -> str:
        """One short line for ``aiorobot run``'s live status display."""
        s = self.stats.recent(self.now().nanoseconds)
        if s.count == 0:
            return f"{self.get_name()}: {self.subscription.topic_name} no messages yet"
        return (
            f"{self.get_name()}: {self.subscription.topic_name} {s.count} msgs {s.rate_hz:5.1f} Hz "
            f"latency p50 {s.latency_p50_us:.0f} us max {s.latency_max_us:.0f} us"
        )

    def summary(self) -> str:
        """The end-of-run summary for ``aiorobot run``."""
        s = self.stats.total()
        if s.count == 0:
            return f"{self.get_name()}: no messages yet on {self.subscription.topic_name}"
        return (
            f"{self.get_name()}: received {s.count} messages on {self.subscription.topic_name}, "
            f"mean rate {s.rate_hz:.1f} Hz, latency p50 {s.latency_p50_us:.0f} us, "
            f"p99 {s.latency_p99_us:.0f} us, max {s.latency_max_us:.0f} us"
        )
