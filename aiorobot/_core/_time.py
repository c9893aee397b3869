"""Time and Duration: integer nanoseconds, ROS 2 semantics."""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass
from typing import Any

__all__ = ["ClockType", "Duration", "Infinite", "Time"]

_NS = 1_000_000_000
_INT64_MAX = 2**63 - 1
_INT64_MIN = -(2**63)


class ClockType(enum.Enum):
    """Which clock a :class:`Time` belongs to (as rcl's ``rcl_clock_type_t``)."""

    ROS_TIME = 1  # system time, or /clock when use_sim_time is on
    SYSTEM_TIME = 2
    STEADY_TIME = 3


def _to_ns(seconds: float | int, nanoseconds: int) -> int:
    if isinstance(seconds, bool) or isinstance(nanoseconds, bool):
        raise TypeError("seconds and nanoseconds must be numbers, not bool")
    if isinstance(seconds, int):
        whole = seconds * _NS
    else:
        whole = round(float(seconds) * _NS)
    return whole + int(nanoseconds)


def _check_int64(ns: int, what: str) -> int:
    if not _INT64_MIN <= ns <= _INT64_MAX:
        raise OverflowError(f"{what}: {ns} ns does not fit in int64 (as rcl stores it)")
    return ns


@dataclass(frozen=True, slots=True, order=False)
class Duration:
    """A signed span of time in integer nanoseconds.

    ``Duration(seconds=0.5)``, ``Duration(nanoseconds=20_000_000)``; arithmetic
    with other durations and numbers, ordering, ``to_msg()`` for
    ``builtin_interfaces/msg/Duration``.
    """

    nanoseconds: int

    def __init__(self, *, seconds: float | int = 0, nanoseconds: int = 0) -> None:
        object.__setattr__(self, "nanoseconds", _check_int64(_to_ns(seconds, nanoseconds), "Duration"))

    @classmethod
    def from_msg(cls, msg: Any) -> Duration:
        """From a ``builtin_interfaces/msg/Duration`` (anything with ``sec`` and ``nanosec``);
        ``TypeError`` for anything else, as rclpy."""
        if not (hasattr(msg, "sec") and hasattr(msg, "nanosec")):
            raise TypeError(f"Duration.from_msg: expected a builtin_interfaces/msg/Duration, found {msg!r}")
        return cls(seconds=int(msg.sec), nanoseconds=int(msg.nanosec))

    def to_msg(self) -> Any:
        from aiorobot.msgs.builtin_interfaces import Duration as DurationMsg

        sec, nanosec = divmod(self.nanoseconds, _NS)
        return DurationMsg(sec=sec, nanosec=nanosec)

    @property
    def seconds(self) -> float:
        return self.nanoseconds / _NS

    def __add__(self, other: object) -> Duration:
        if isinstance(other, Duration):
            return Duration(nanoseconds=self.nanoseconds + other.nanoseconds)
        return NotImplemented

    def __sub__(self, other: object) -> Duration:
        if isinstance(other, Duration):
            return Duration(nanoseconds=self.nanoseconds - other.nanoseconds)
        return NotImplemented

    def __mul__(self, factor: object) -> Duration:
        if isinstance(factor, float) and not math.isfinite(factor):
            if factor == math.inf:
                return Infinite
            raise ValueError(f"cannot multiply {self!r} by {factor!r}")
        if isinstance(factor, (int, float)) and not isinstance(factor, bool):
            return Duration(nanoseconds=round(self.nanoseconds * factor))
        return NotImplemented

    __rmul__ = __mul__

    def __truediv__(self, other: object) -> Duration | float:
        if isinstance(other, Duration):
            return self.nanoseconds / other.nanoseconds
        if isinstance(other, (int, float)) and not isinstance(other, bool):
            return Duration(nanoseconds=round(self.nanoseconds / other))
        return NotImplemented

    def __neg__(self) -> Duration:
        return Duration(nanoseconds=-self.nanoseconds)

    def __abs__(self) -> Duration:
        return Duration(nanoseconds=abs(self.nanoseconds))

    def __lt__(self, other: Duration) -> bool:
        return self.nanoseconds < _duration_ns(other)

    def __le__(self, other: Duration) -> bool:
        return self.nanoseconds <= _duration_ns(other)

    def __gt__(self, other: Duration) -> bool:
        return self.nanoseconds > _duration_ns(other)

    def __ge__(self, other: Duration) -> bool:
        return self.nanoseconds >= _duration_ns(other)

    def __repr__(self) -> str:
        return f"Duration(nanoseconds={self.nanoseconds})"

    def __str__(self) -> str:
        if self.nanoseconds == _INT64_MAX:
            return "Infinite"
        return f"{self.nanoseconds} nanoseconds"


#: The longest duration rcl can store (``RMW_DURATION_INFINITE``); ``str(Infinite) == "Infinite"``.
Infinite = Duration(nanoseconds=_INT64_MAX)


def _duration_ns(other: object) -> int:
    if not isinstance(other, Duration):
        raise TypeError(f"cannot compare Duration with {type(other).__name__}")
    return other.nanoseconds


@dataclass(frozen=True, slots=True, eq=False)
class Time:
    """A point in time: integer nanoseconds since the clock's epoch (0 to 2**63 - 1).

    ``Time()`` is zero, which tf reads as "the latest available". Times of
    different clock types do not compare (``==`` included: ``TypeError``) or
    subtract, as in rclpy; a time is never equal to a non-time.

    rclpy difference: a float ``seconds`` is rounded to the nearest nanosecond
    (rclpy truncates, so ``Time(seconds=0.3)`` is 299999999 ns there).
    """

    nanoseconds: int
    clock_type: ClockType

    def __init__(
        self,
        *,
        seconds: float | int = 0,
        nanoseconds: int = 0,
        clock_type: ClockType = ClockType.ROS_TIME,
    ) -> None:
        if not isinstance(clock_type, ClockType):
            raise TypeError(f"clock_type: expected a ClockType (e.g. ClockType.SYSTEM_TIME), found {clock_type!r}")
        ns = _to_ns(seconds, nanoseconds)
        if ns < 0:
            raise ValueError(f"Time must not be negative, got {ns} ns")
        if ns > _INT64_MAX:
            raise OverflowError(f"Time: {ns} ns does not fit in int64 (as rcl stores it)")
        object.__setattr__(self, "nanoseconds", ns)
        object.__setattr__(self, "clock_type", clock_type)

    @classmethod
    def from_msg(cls, msg: Any, clock_type: ClockType = ClockType.ROS_TIME) -> Time:
        """From a ``builtin_interfaces/msg/Time`` (anything with ``sec`` and ``nanosec``);
        ``TypeError`` for anything else, as rclpy."""
        if not (hasattr(msg, "sec") and hasattr(msg, "nanosec")):
            raise TypeError(f"Time.from_msg: expected a builtin_interfaces/msg/Time, found {msg!r}")
        return cls(seconds=int(msg.sec), nanoseconds=int(msg.nanosec), clock_type=clock_type)

    def to_msg(self) -> Any:
        from aiorobot.msgs.builtin_interfaces import Time as TimeMsg

        sec, nanosec = divmod(self.nanoseconds, _NS)
        return TimeMsg(sec=sec, nanosec=nanosec)

    @property
    def seconds(self) -> float:
        return self.nanoseconds / _NS

    def seconds_nanoseconds(self) -> tuple[int, int]:
        return divmod(self.nanoseconds, _NS)

    def _check(self, other: Time) -> int:
        if not isinstance(other, Time):
            raise TypeError(f"expected a Time, got {type(other).__name__}")
        if other.clock_type != self.clock_type:
            raise TypeError(
                f"cannot combine times of different clocks: {self.clock_type.name} "
                f"and {other.clock_type.name}"
            )
        return other.nanoseconds

    def __add__(self, other: object) -> Time:
        if isinstance(other, Duration):
            return Time(nanoseconds=self.nanoseconds + other.nanoseconds, clock_type=self.clock_type)
        return NotImplemented

    __radd__ = __add__

    def __sub__(self, other: object) -> Any:
        if isinstance(other, Time):
            return Duration(nanoseconds=self.nanoseconds - self._check(other))
        if isinstance(other, Duration):
            return Time(nanoseconds=self.nanoseconds - other.nanoseconds, clock_type=self.clock_type)
        return NotImplemented

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Time):
            return NotImplemented
        return self.nanoseconds == self._check(other)

    def __ne__(self, other: object) -> bool:
        if not isinstance(other, Time):
            return NotImplemented
        return self.nanoseconds != self._check(other)

    def __hash__(self) -> int:
        return hash((self.nanoseconds, self.clock_type))

    def __lt__(self, other: Time) -> bool:
        return self.nanoseconds < self._check(other)

    def __le__(self, other: Time) -> bool:
        return self.nanoseconds <= self._check(other)

    def __gt__(self, other: Time) -> bool:
        return self.nanoseconds > self._check(other)

    def __ge__(self, other: Time) -> bool:
        return self.nanoseconds >= self._check(other)

    def __repr__(self) -> str:
        return f"Time(nanoseconds={self.nanoseconds}, clock_type={self.clock_type.name})"
