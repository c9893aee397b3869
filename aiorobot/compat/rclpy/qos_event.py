"""``rclpy.qos_event``: rclpy's deprecated name of ``rclpy.event_handler`` (warns on import, as rclpy)."""

import warnings

from .event_handler import *  # noqa: F401, F403
from .event_handler import __all__  # noqa: F401

warnings.warn("importing 'qos_event' is deprecated; import 'event_handler' instead")
