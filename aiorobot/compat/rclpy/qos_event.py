"""``rclpy.qos_event``: rclpy's deprecated name of ``rclpy.event_handler``.

A program importing ``rclpy.qos_event`` gets rclpy's deprecation warning (the import
aliases emit it, so importing this module directly stays quiet).
"""

from .event_handler import *  # noqa: F401, F403
from .event_handler import __all__  # noqa: F401
