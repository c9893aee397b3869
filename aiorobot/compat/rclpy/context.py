"""``rclpy.context``."""

from .._context import Context

__all__ = ["Context"]
