"""``rclpy.service``."""

from ..._services import Service

__all__ = ["Service"]
