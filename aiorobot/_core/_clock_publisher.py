"""``ClockPublisher``: the node that drives sim time by publishing ``/clock``."""

from __future__ import annotations

from typing import Any

from ._node import Node
from ._qos import QoSProfile
from ._time import Time

__all__ = ["ClockPublisher"]


class ClockPublisher(Node):
    """Publishes ``rosgraph_msgs/msg/Clock`` on ``/clock`` when told to (simulators, bag playback, tests).

    Every ``Runtime(use_sim_time=True)`` in the graph follows what it publishes.
    """

    def __init__(self, name: str = "sim_clock", **kw: Any) -> None:
        super().__init__(name, **kw)
        from ..msgs.rosgraph_msgs import Clock

        self._msg_type = Clock
        self._pub = self.create_publisher(Clock, "/clock", QoSProfile(depth=1))
        self.time_ns = 0

    def publish_time(self, nanoseconds: int) -> None:
        """Publish ``nanoseconds`` as the current sim time."""
        self.time_ns = nanoseconds
        msg = self._msg_type()
        msg.clock = Time(nanoseconds=nanoseconds).to_msg()
        self._pub.publish(msg)
