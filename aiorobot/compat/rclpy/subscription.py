"""``rclpy.subscription``."""

from ..._pubsub import Subscription

__all__ = ["Subscription"]
