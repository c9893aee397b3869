"""``rclpy.publisher``."""

from ..._core._pubsub import Publisher

__all__ = ["Publisher"]
