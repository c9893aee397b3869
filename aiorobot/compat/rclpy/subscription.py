"""``rclpy.subscription``."""

from ..._core._pubsub import Subscription

__all__ = ["Subscription"]
