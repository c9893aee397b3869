"""``rclpy.impl.logging_severity``: rcutils' severity levels (the numbers Python's logging uses too)."""

from __future__ import annotations

import enum

__all__ = ["LoggingSeverity"]


class LoggingSeverity(enum.IntEnum):
    """rcutils' ``RCUTILS_LOG_SEVERITY``; UNSET is Python's NOTSET, FATAL its CRITICAL."""

    UNSET = 0
    DEBUG = 10
    INFO = 20
    WARN = 30
    ERROR = 40
    FATAL = 50
