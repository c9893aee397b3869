"""``rclpy.time``."""

from ..._core._time import Time

__all__ = ["Time"]
