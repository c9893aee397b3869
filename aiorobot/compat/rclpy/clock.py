"""``rclpy.clock``."""

from ..._clock import Clock, JumpHandle, JumpThreshold, ROSClock, TimeJump
from ..._time import ClockType

__all__ = ["Clock", "ClockType", "JumpHandle", "JumpThreshold", "ROSClock", "TimeJump"]
