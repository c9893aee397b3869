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

``/rosout``: as in ROS 2, every node (unless made with ``enable_rosout=False``)
publishes what its logger emits as ``rcl_interfaces/msg/Log`` on ``/rosout``
with rclpy's ``qos_profile_rosout_default`` (reliable, transient local, keep
last 1000, lifespan 10 s), so ``aiorobot log``, a bag recorder and Foxglove's
Log panel see every process's lines, and a late joiner gets the recent ones.
The ``name`` field is rcl's logger name (``/robot/talker`` logs as ``robot.talker``).
"""

from __future__ import annotations

import logging
import os
import sys
import threading
import time
from typing import TYPE_CHECKING, Any

from ._qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from ._time import Duration

if TYPE_CHECKING:
    from ._clock import Clock
    from ._pubsub import Publisher

__all__ = ["LEVELS", "ROSOUT_QOS", "NodeFormatter", "NodeLogger", "parse_level", "setup_logging"]

#: rclpy's ``qos_profile_rosout_default`` (rcl's ``rmw_qos_profile_rosout_default``)
ROSOUT_QOS = QoSProfile(
    reliability=ReliabilityPolicy.RELIABLE,
    durability=DurabilityPolicy.TRANSIENT_LOCAL,
    history=HistoryPolicy.KEEP_LAST,
    depth=1000,
    lifespan=Duration(seconds=10),
)

#: set while a thread publishes a /rosout line: what that publish logs is not published again
class _RosoutGuard(threading.local):
    active = False  # a class default: reading it never raises (an AttributeError is slow)


_in_rosout = _RosoutGuard()

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
        self._rosout: Publisher[Any] | None = None
        #: rcl's logger name: ``/robot/talker`` -> ``robot.talker``
        self.rosout_name = dotted if dotted != "root" else ""

    def _attach_rosout(self, publisher: Publisher[Any] | None) -> None:
        """Publish every emitted record on ``publisher`` (the node's ``/rosout``), children too."""
        self._rosout = publisher

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
        child._rosout = self._rosout
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
        if self._rosout is not None:
            self._publish_rosout(level, msg, args, stamp, stacklevel + 1, exc_info)
        return True

    def _publish_rosout(
        self, level: int, msg: str, args: tuple[Any, ...], stamp: int, stacklevel: int, exc_info: Any
    ) -> None:
        """One ``rcl_interfaces/msg/Log`` on ``/rosout``; a failure here is never the caller's."""
        pub = self._rosout
        if pub is None or pub.destroyed or _in_rosout.active:
            return
        _in_rosout.active = True
        try:
            from ..msgs.builtin_interfaces import Time as TimeMsg
            from ..msgs.rcl_interfaces import Log

            text = str(msg) % args if args else str(msg)
            if exc_info:
                text += "\n" + _format_exc(exc_info)
            caller = sys._getframe(stacklevel)
            sec, nanosec = divmod(max(int(stamp), 0), 1_000_000_000)
            pub.publish(
                Log(
                    stamp=TimeMsg(sec=sec, nanosec=nanosec),
                    # the logging levels are rcl's numbers (DEBUG 10 ... FATAL 50); others round down
                    level=min(max(level // 10 * 10, Log.DEBUG), Log.FATAL),
                    name=self.rosout_name,
                    msg=text,
                    file=os.path.basename(caller.f_code.co_filename),
                    function=caller.f_code.co_name,
                    line=caller.f_lineno,
                )
            )
        except Exception:  # a closed runtime, a bad format string: the record went to logging already
            pass
        finally:
            _in_rosout.active = False

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


def _format_exc(exc_info: Any) -> str:
    import traceback

    if exc_info is True:
        exc_info = sys.exc_info()
    elif isinstance(exc_info, BaseException):
        exc_info = (type(exc_info), exc_info, exc_info.__traceback__)
    if not isinstance(exc_info, tuple) or exc_info[0] is None:
        return ""
    return "".join(traceback.format_exception(*exc_info)).rstrip()


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
