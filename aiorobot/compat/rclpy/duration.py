"""``rclpy.duration``."""

from ..._core._time import Duration, Infinite

__all__ = ["Duration", "Infinite"]
