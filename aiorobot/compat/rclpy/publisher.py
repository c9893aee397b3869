"""``rclpy.publisher``."""

from ..._pubsub import Publisher

__all__ = ["Publisher"]
