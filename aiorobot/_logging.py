"""Node loggers: messages carry the node name, the level and the runtime clock's time.

Records go through the standard :mod:`logging` hierarchy under ``aiorobot.node.*``
(so applications configure handlers as usual); :func:`setup_logging` installs
the ROS-style format ``[INFO] [1700000000.123456789] [/ns/node]: message``.
"""

from __future__ import annotations

import logging
import sys
import time
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from ._clock import Clock

__all__ = ["LEVELS", "NodeFormatter", "NodeLogger", "parse_level", "setup_logging"]

LEVELS = {
    "debug": logging.DEBUG,
    "info": logging.INFO,
    "warn": logging.WARNING,
    "warning": logging.WARNING,
    "error": logging.ERROR,
    "fatal": logging.CRITICAL,
}


def parse_level(level: str | int) -> int:
    if isinstance(level, int) and not isinstance(level, bool):
        return level
    if isinstance(level, str) and level.lower() in LEVELS:
        return LEVELS[level.lower()]
    raise ValueError(
        f"log level: expected one of {', '.join(sorted(set(LEVELS) - {'warn'}))}, found {level!r}"
    )


class NodeLogger:
    """A node's logger, as rclpy's: ``info(msg, throttle_duration_sec=..., once=...)``."""

    def __init__(self, node_fqn: str, clock: Clock | None = None) -> None:
        self.name = node_fqn
        dotted = node_fqn.strip("/").replace("/", ".") or "root"
        self._logger = logging.getLogger(f"aiorobot.node.{dotted}")
        self._clock = clock
        self._last_emit: dict[tuple[str, int], float] = {}
        self._once: set[tuple[str, int]] = set()

    def _bind_clock(self, clock: Clock) -> None:
        self._clock = clock

    def __repr__(self) -> str:
        return f"<NodeLogger {self.name} level={logging.getLevelName(self.get_effective_level())}>"

    def set_level(self, level: str | int) -> None:
        self._logger.setLevel(parse_level(level))

    def get_effective_level(self) -> int:
        return self._logger.getEffectiveLevel()

    def is_enabled_for(self, level: str | int) -> bool:
        return self._logger.isEnabledFor(parse_level(level))

    def get_child(self, suffix: str) -> NodeLogger:
        child = NodeLogger(f"{self.name}.{suffix}", self._clock)
        return child

    def log(
        self,
        level: int,
        msg: str,
        *args: Any,
        throttle_duration_sec: float | None = None,
        once: bool = False,
        skip_first: bool = False,
        exc_info: Any = None,
        stacklevel: int = 1,
    ) -> bool:
        """Log ``msg``; returns whether it was emitted (throttling and ``once`` may suppress it)."""
        if not self._logger.isEnabledFor(level):
            return False
        if throttle_duration_sec is not None or once or skip_first:
            caller = sys._getframe(stacklevel)
            key = (caller.f_code.co_filename, caller.f_lineno)
            if once:
                if key in self._once:
                    return False
                self._once.add(key)
            if throttle_duration_sec is not None or skip_first:
                now = time.monotonic()
                last = self._last_emit.get(key)
                if last is None:
                    self._last_emit[key] = now
                    if skip_first:
                        return False
                elif throttle_duration_sec is not None and now - last < throttle_duration_sec:
                    return False
                else:
                    self._last_emit[key] = now
        stamp = self._clock.now_ns() if self._clock is not None else time.time_ns()
        self._logger.log(
            level,
            msg,
            *args,
            exc_info=exc_info,
            extra={"node": self.name, "ros_time_ns": stamp},
            stacklevel=stacklevel + 1,
        )
        return True

    def debug(self, msg: str, *args: Any, **kw: Any) -> bool:
        return self.log(logging.DEBUG, msg, *args, stacklevel=2, **kw)

    def info(self, msg: str, *args: Any, **kw: Any) -> bool:
        return self.log(logging.INFO, msg, *args, stacklevel=2, **kw)

    def warning(self, msg: str, *args: Any, **kw: Any) -> bool:
        return self.log(logging.WARNING, msg, *args, stacklevel=2, **kw)

    warn = warning

    def error(self, msg: str, *args: Any, **kw: Any) -> bool:
        return self.log(logging.ERROR, msg, *args, stacklevel=2, **kw)

    def fatal(self, msg: str, *args: Any, **kw: Any) -> bool:
        return self.log(logging.CRITICAL, msg, *args, stacklevel=2, **kw)

    def exception(self, msg: str, *args: Any, **kw: Any) -> bool:
        return self.log(logging.ERROR, msg, *args, exc_info=True, stacklevel=2, **kw)


class NodeFormatter(logging.Formatter):
    """``[LEVEL] [sec.nanosec] [node]: message`` — the format ROS 2 users read every day."""

    def format(self, record: logging.LogRecord) -> str:
        stamp = getattr(record, "ros_time_ns", None)
        if stamp is None:
            stamp = int(record.created * 1e9)
        sec, nsec = divmod(int(stamp), 1_000_000_000)
        node = getattr(record, "node", None) or record.name
        level = "WARN" if record.levelno == logging.WARNING else record.levelname
        text = f"[{level}] [{sec}.{nsec:09d}] [{node}]: {record.getMessage()}"
        if record.exc_info:
            text += "\n" + self.formatException(record.exc_info)
        return text


def setup_logging(level: str | int = "info", stream: Any = None) -> logging.Handler:
    """Send ``aiorobot`` logs to ``stream`` (stderr) in the node format; returns the handler.

    Applications call this once (the CLI does); libraries never do.
    """
    handler = logging.StreamHandler(stream if stream is not None else sys.stderr)
    handler.setFormatter(NodeFormatter())
    root = logging.getLogger("aiorobot")
    root.addHandler(handler)
    root.setLevel(parse_level(level))
    return handler
