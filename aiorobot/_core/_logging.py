"""Node loggers: messages carry the node name, the level and the runtime clock's time.

Records go through the standard :mod:`logging` hierarchy under ``aiorobot.node.*``
(so applications configure handlers as usual); :func:`setup_logging` installs
the ROS-style format ``[INFO] [1700000000.123456789] [/ns/node]: message``.

As in rclpy, node loggers print INFO and above to stderr in that format by
default: when the first node logger is made and the application has configured
no logging (no handler on the root or ``aiorobot`` logger), a default handler is
put on the ``aiorobot`` logger. It steps aside as soon as the application
configures logging itself (``logging.basicConfig(...)``, :func:`setup_logging`,
a handler of its own); ``logging.getLogger("aiorobot").setLevel("WARNING")``
quietens it, ``node.get_logger().set_level("debug")`` shows more of one node.
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


class _DefaultHandler(logging.StreamHandler):  # type: ignore[type-arg]
    """stderr in the node format, for applications that configured no logging of their own."""

    def __init__(self) -> None:
        super().__init__(sys.stderr)
        self.setFormatter(NodeFormatter())

    def emit(self, record: logging.LogRecord) -> None:
        root = logging.getLogger("aiorobot")
        if logging.root.handlers or any(h is not self for h in root.handlers):
            return  # the application configured logging after all: its handlers have it
        self.stream = sys.stderr  # looked up at each record, so redirections apply
        super().emit(record)


_default_handler: _DefaultHandler | None = None


def _install_default_handler() -> None:
    """Give node loggers rclpy's default (INFO+ to stderr) unless logging is configured."""
    global _default_handler
    if _default_handler is not None:
        return
    logger = logging.getLogger("aiorobot")
    if logging.root.handlers or logger.handlers:
        return
    _default_handler = _DefaultHandler()
    logger.addHandler(_default_handler)
    if logger.level == logging.NOTSET:
        logger.setLevel(logging.INFO)


class NodeLogger:
    """A node's logger, as rclpy's: ``info(msg, throttle_duration_sec=..., once=...)``.

    Prints INFO and above to stderr by default when the application configured no
    logging (see the module docstring for how to change it).
    """

    def __init__(self, node_fqn: str, clock: Clock | None = None) -> None:
        _install_default_handler()
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
    if _default_handler is not None:
        root.removeHandler(_default_handler)
    root.addHandler(handler)
    root.setLevel(parse_level(level))
    return handler
