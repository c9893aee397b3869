"""``rclpy.logging``: named loggers with rclpy's methods (``info``, ``warn``, ``once=True``, throttling)."""

from __future__ import annotations

from typing import Any

from ..._logging import NodeLogger

__all__ = ["LoggingSeverity", "get_logger", "set_logger_level"]

import enum


class LoggingSeverity(enum.IntEnum):
    UNSET = 0
    DEBUG = 10
    INFO = 20
    WARN = 30
    ERROR = 40
    FATAL = 50


def get_logger(name: str) -> NodeLogger:
    return NodeLogger(name)


def set_logger_level(name: str, level: Any) -> None:
    NodeLogger(name).set_level(level.name.lower() if isinstance(level, LoggingSeverity) else level)
