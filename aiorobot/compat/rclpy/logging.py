"""``rclpy.logging``: named loggers with rclpy's methods (``info``, ``warn``, ``once=True``, throttling).

rclpy's logger ``a.b`` (a node ``/a/b``'s) is Python's ``aiorobot.node.a.b``: levels set here
apply to the node's ``get_logger()``, and UNSET leaves it to its parent's.
"""

from __future__ import annotations

import logging
from typing import Any

from ..._core._logging import NodeLogger
from .impl.logging_severity import LoggingSeverity

__all__ = [
    "LoggingSeverity", "get_logger", "get_logger_effective_level", "get_logger_level",
    "get_logging_severity_from_string", "set_logger_level",
]


def _python_logger(name: str) -> logging.Logger:
    return logging.getLogger(f"aiorobot.node.{name.strip('/').replace('/', '.') or 'root'}")


def get_logger(name: str) -> NodeLogger:
    return NodeLogger(name)


def set_logger_level(name: str, level: Any, detailed_error: bool = False) -> None:
    """Set logger ``name``'s own level; ``ValueError`` for a level that is not a ``LoggingSeverity``."""
    _python_logger(name).setLevel(int(LoggingSeverity(level)))


def get_logger_level(name: str) -> LoggingSeverity:
    """Logger ``name``'s own level (UNSET unless one was set)."""
    return LoggingSeverity(_python_logger(name).level)


def get_logger_effective_level(name: str) -> LoggingSeverity:
    return LoggingSeverity(_python_logger(name).getEffectiveLevel())


def get_logging_severity_from_string(log_severity: str) -> LoggingSeverity:
    try:
        return LoggingSeverity[log_severity.upper()]
    except KeyError:
        raise RuntimeError(
            f"get_logging_severity_from_string: expected one of "
            f"{', '.join(s.name for s in LoggingSeverity)}, found {log_severity!r}"
        ) from None
