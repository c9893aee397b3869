"""``rclpy.service``."""

from ..._core._services import Service

__all__ = ["Service"]
