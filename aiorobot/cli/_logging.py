"""Logging set-up for the command line: the ``aiorobot`` logger hierarchy to stderr.

Done by the CLI, never at import time: a library must not configure logging for its users.
"""

from __future__ import annotations

import logging
import sys
from typing import TextIO

from aiorobot._core._logging import NodeFormatter, parse_level

__all__ = ["configure_logging", "installed_handler"]


class _RichNodeFormatter(logging.Formatter):
    """``[sec.nanosec] [node]: message``; rich's handler shows the level itself."""

    def format(self, record: logging.LogRecord) -> str:
        stamp = getattr(record, "ros_time_ns", None)
        if stamp is None:
            stamp = int(record.created * 1e9)
        sec, nsec = divmod(int(stamp), 1_000_000_000)
        node = getattr(record, "node", None) or record.name
        text = f"[{sec}.{nsec:09d}] [{node}]: {record.getMessage()}"
        if record.exc_info:
            text += "\n" + self.formatException(record.exc_info)
        return text


def configure_logging(level: str, stream: TextIO | None = None) -> logging.Handler:
    """Send records of the ``aiorobot`` loggers at ``level`` and above to ``stream``.

    ``stream`` defaults to stderr; on a terminal the output is rich's, otherwise one
    plain line per record (``[INFO] [sec.nanosec] [/node]: message``). Calling it again
    replaces the handler it installed. Returns the installed handler.
    """
    stream = sys.stderr if stream is None else stream
    handler: logging.Handler
    if stream.isatty():
        from rich.console import Console
        from rich.logging import RichHandler

        # Console(stderr=True) looks sys.stderr up at each write, so a rich Live display that
        # redirects stderr keeps these lines above its status line.
        console = Console(stderr=True) if stream is sys.stderr else Console(file=stream)
        handler = RichHandler(console=console, show_time=False, show_path=False, markup=False)
        handler.setFormatter(_RichNodeFormatter())
    else:
        handler = logging.StreamHandler(stream)
        handler.setFormatter(NodeFormatter())
    logger = logging.getLogger("aiorobot")
    from aiorobot._core import _logging

    if _logging._default_handler is not None:
        logger.removeHandler(_logging._default_handler)
    for old in [h for h in logger.handlers if getattr(h, "_aiorobot_cli", False)]:
        logger.removeHandler(old)
    setattr(handler, "_aiorobot_cli", True)  # marks the handler this CLI installed  # noqa: B010
    logger.addHandler(handler)
    logger.setLevel(parse_level(level))
    logger.propagate = False
    return handler


def installed_handler() -> logging.Handler | None:
    """The handler :func:`configure_logging` installed on the ``aiorobot`` logger, if any."""
    for handler in logging.getLogger("aiorobot").handlers:
        if getattr(handler, "_aiorobot_cli", False):
            return handler
    return None
