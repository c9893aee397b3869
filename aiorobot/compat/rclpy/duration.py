"""``rclpy.duration``."""

from ..._time import Duration, Infinite

__all__ = ["Duration", "Infinite"]
