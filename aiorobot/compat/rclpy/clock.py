"""``rclpy.clock``."""

from ..._core._clock import Clock, JumpHandle, JumpThreshold, ROSClock, TimeJump
from ..._core._time import ClockType

__all__ = ["Clock", "ClockType", "JumpHandle", "JumpThreshold", "ROSClock", "TimeJump"]
