"""``rclpy.time``."""

from ..._time import Time

__all__ = ["Time"]
