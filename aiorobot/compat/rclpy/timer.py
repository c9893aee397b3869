"""``rclpy.timer``."""

from ..._core._timer import Timer, TimerInfo
from .._node import Rate

__all__ = ["Rate", "Timer", "TimerInfo"]
