"""``rclpy.client``: blocking ``call`` / ``wait_for_service``, ``call_async`` futures."""

from .._node import Client

__all__ = ["Client"]
