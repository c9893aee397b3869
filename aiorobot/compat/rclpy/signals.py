"""``rclpy.signals``: options accepted; SIGINT and SIGTERM are always handled as rclpy's default (ALL)."""

import enum

__all__ = ["SignalHandlerOptions"]


class SignalHandlerOptions(enum.IntEnum):
    NO = 0
    SIGINT = 1
    SIGTERM = 2
    ALL = 3
