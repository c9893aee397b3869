"""Timers and rates with absolute deadlines.

A timer's n-th deadline is ``start + n * period``: no drift, however late a
callback ran. When a callback overruns one or more periods, the missed
deadlines are skipped (counted as overruns) instead of firing in a burst. On
wall time, deadlines are monotonic-clock instants waited for by the loop's
waker (sub-millisecond on Linux); under sim time they are sim-clock instants
woken by ``/clock``, and a backwards jump restarts the timer with a warning,
as ROS 2 does.
"""

from __future__ import annotations

import asyncio
import functools
import inspect
import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from ._clock import ClockJump
from ._handoff import post, wake
from ._time import ClockType, Time

if TYPE_CHECKING:
    from ._clock import Clock
    from ._groups import CallbackGroup
    from ._node import Node

__all__ = ["Rate", "Timer", "TimerInfo", "TimerStatistics"]


class TimerInfo:
    """When a timer call was due and when it ran (rclpy's ``TimerInfo``), on the timer's clock.

    A timer callback that takes one argument (or has a parameter annotated
    ``TimerInfo``) receives it.
    """

    __slots__ = ("_actual", "_expected")

    def __init__(
        self, *, expected_call_time: int = 0, actual_call_time: int = 0, clock_type: ClockType = ClockType.SYSTEM_TIME
    ) -> None:
        if not isinstance(clock_type, ClockType):
            raise TypeError(f"clock_type must be a ClockType, got {clock_type!r}")
        if expected_call_time < 0 or actual_call_time < 0:
            raise ValueError(
                f"call times must not be negative, got expected_call_time={expected_call_time}, "
                f"actual_call_time={actual_call_time}"
            )
        self._expected = Time(nanoseconds=expected_call_time, clock_type=clock_type)
        self._actual = Time(nanoseconds=actual_call_time, clock_type=clock_type)

    def __repr__(self) -> str:
        return f"<TimerInfo expected={self._expected.nanoseconds} actual={self._actual.nanoseconds}>"

    @property
    def expected_call_time(self) -> Time:
        return self._expected

    @property
    def actual_call_time(self) -> Time:
        return self._actual


def _info_parameter(callback: Callable[..., Any]) -> str | None:
    """How ``callback`` wants its :class:`TimerInfo`: a parameter name, ``""`` for positionally, or None.

    As rclpy, a parameter annotated ``TimerInfo`` gets it by name; beyond rclpy, a
    callback with exactly one required positional parameter gets it positionally.
    """
    try:
        sig = inspect.signature(callback)
    except (TypeError, ValueError):
        return None
    required = 0
    for p in sig.parameters.values():
        if p.annotation is TimerInfo or p.annotation == "TimerInfo":
            return p.name
        if p.kind in (inspect.Parameter.POSITIONAL_ONLY, inspect.Parameter.POSITIONAL_OR_KEYWORD):
            if p.default is inspect.Parameter.empty:
                required += 1
    return "" if required == 1 else None

#: How many recent lateness samples a timer keeps for its percentiles.
_WINDOW = 4096


@dataclass(frozen=True, slots=True)
class TimerStatistics:
    """What a timer has done so far. Lateness is how long after its deadline a callback started."""

    calls: int
    overruns: int
    lateness_p50_sec: float
    lateness_p99_sec: float
    lateness_max_sec: float
    period_sec: float


def _percentile(sorted_values: list[int], q: float) -> int:
    if not sorted_values:
        return 0
    k = (len(sorted_values) - 1) * q
    lo = int(k)
    hi = min(lo + 1, len(sorted_values) - 1)
    return round(sorted_values[lo] + (sorted_values[hi] - sorted_values[lo]) * (k - lo))


class Timer:
    """Calls ``callback`` every ``period_sec``; created by ``Node.create_timer``.

    A callback taking one argument gets a :class:`TimerInfo` (when the call was
    due and when it ran, on the node clock), as rclpy passes one to a parameter
    annotated ``TimerInfo``. ``with node.create_timer(...) as timer:`` destroys it
    at the end of the block.
    """

    def __init__(
        self,
        node: Node,
        period_sec: float,
        callback: Callable[[], Any],
        group: CallbackGroup,
        *,
        autostart: bool = True,
    ) -> None:
        if isinstance(period_sec, bool) or not isinstance(period_sec, (int, float)) or not period_sec > 0:
            raise ValueError(f"timer period: expected a number of seconds > 0, got {period_sec!r}")
        self.node = node
        self.period_ns = round(period_sec * 1e9)
        self.callback = callback
        self._info_param = _info_parameter(callback)
        self._last_call_ns: int | None = None
        self.callback_group = group
        self._task: asyncio.Task[None] | None = None
        self._cancelled = not autostart
        self._calls = 0
        self._overruns = 0
        self._lateness: deque[int] = deque(maxlen=_WINDOW)
        self._max_late = 0
        self._next_ns: int | None = None
        self._restart = False
        #: how the watchdog and the culprit watch name this timer's callbacks
        self._entity_name = f"timer {self.period_ns / 1e9:g}s"
        self._wake: asyncio.Future[None] | None = None
        self.destroyed = False

    def __repr__(self) -> str:
        state = "cancelled" if self._cancelled else "running"
        return f"<Timer {self.period_ns / 1e9:g}s {state} calls={self._calls} of {self.node.get_fully_qualified_name()}>"

    @property
    def timer_period_ns(self) -> int:
        return self.period_ns

    @timer_period_ns.setter
    def timer_period_ns(self, value: int) -> None:
        """Change the period (rclpy's setter): the grid restarts from now with the new period."""
        if isinstance(value, bool) or not isinstance(value, int) or value <= 0:
            raise ValueError(f"timer_period_ns: expected an int > 0 (nanoseconds), got {value!r}")
        self.period_ns = value
        self._entity_name = f"timer {value / 1e9:g}s"
        if not self._cancelled:
            self.reset()

    def is_ready(self) -> bool:
        """True when a call is due now (rclpy's ``is_ready``)."""
        until = self.time_until_next_call()
        return until is not None and until <= 0

    @property
    def clock(self) -> Clock:
        """The clock the timer runs on: the node's."""
        return self.node._clock

    def time_until_next_call(self) -> int | None:
        """Nanoseconds until the next call (negative when overdue); ``None`` when cancelled (rclpy)."""
        if self._cancelled:
            return None
        if self._next_ns is None:
            return self.period_ns
        return self._next_ns - self._now()

    def time_since_last_call(self) -> int:
        """Nanoseconds since the last call started (or since the timer started, before any)."""
        if self._last_call_ns is not None:
            return self._now() - self._last_call_ns
        if self._next_ns is None:
            return 0
        return self._now() - (self._next_ns - self.period_ns)

    def __enter__(self) -> Timer:
        return self

    def __exit__(self, *exc: object) -> None:
        self.destroy()

    def _callback_for(self, deadline_ns: int) -> Callable[[], Any]:
        """The callback as the executor calls it: with a :class:`TimerInfo` when it takes one."""
        if self._info_param is None:
            return self.callback
        return functools.partial(self._call_with_info, deadline_ns)

    def _call_with_info(self, deadline_ns: int) -> Any:
        clock = self.node._clock
        actual = clock.now_ns()
        # deadlines are monotonic instants on wall time: express the due time on the node clock
        expected = deadline_ns if clock.use_sim_time else actual - (time.monotonic_ns() - deadline_ns)
        info = TimerInfo(
            expected_call_time=max(expected, 0), actual_call_time=max(actual, 0), clock_type=clock.clock_type
        )
        if self._info_param:
            return self.callback(**{self._info_param: info})
        return self.callback(info)

    @property
    def stats(self) -> TimerStatistics:
        return self.statistics()

    def statistics(self) -> TimerStatistics:
        late = sorted(self._lateness)
        return TimerStatistics(
            calls=self._calls,
            overruns=self._overruns,
            lateness_p50_sec=_percentile(late, 0.5) / 1e9,
            lateness_p99_sec=_percentile(late, 0.99) / 1e9,
            lateness_max_sec=self._max_late / 1e9,
            period_sec=self.period_ns / 1e9,
        )

    def is_canceled(self) -> bool:
        return self._cancelled

    is_cancelled = is_canceled

    def cancel(self) -> None:
        """Stop firing. A callback already running finishes."""
        self._cancelled = True
        self.node._call_soon(self._poke)

    def reset(self) -> None:
        """Restart the period from now (and resume a cancelled timer), as rclpy's ``reset``."""
        self._cancelled = False
        if self.node._loop is not None:
            self._next_ns = self._now() + self.period_ns
        self._restart = True
        self.node._call_soon(self._poke)

    def _poke(self) -> None:
        if self._task is None and not self.destroyed and self.node._loop is not None:
            self._start()
        wake = self._wake
        if wake is not None and not wake.done():
            wake.set_result(None)

    def _anchor(self) -> None:
        """Start the deadline grid now. Called on the thread that adds the node or creates the
        timer, so a clock that moves before the node's loop picks the timer up cannot shift it."""
        self._next_ns = self._now() + self.period_ns

    def _start(self) -> None:
        if self._task is None and not self.destroyed:
            if self._next_ns is None:
                self._anchor()
            self._restart = False
            self._task = self.node._create_task(self._run(), name=f"timer {self.period_ns / 1e9:g}s of {self.node.get_fully_qualified_name()}")

    def _now(self) -> int:
        clock = self.node._clock
        return clock.now_ns() if clock.use_sim_time else time.monotonic_ns()

    async def _sleep_until(self, deadline: int) -> None:
        """Wait for the deadline, or for cancel/reset to poke us."""
        node = self.node
        wake = asyncio.get_running_loop().create_future()  # the node's loop
        self._wake = wake
        clock = node._clock
        if clock.use_sim_time:
            clock.add_waiter(deadline, wake)
        else:
            assert node._waker is not None, "a running timer belongs to a bound node"
            node._waker.add(deadline, wake)
        try:
            await wake  # raises ClockJump when sim time jumps back
        finally:
            self._wake = None

    async def _run(self) -> None:
        node = self.node
        loop = asyncio.get_running_loop()
        while True:
            if self._cancelled:
                wake = loop.create_future()
                self._wake = wake
                try:
                    await wake
                finally:
                    self._wake = None
                continue
            self._restart = False
            deadline = self._next_ns
            assert deadline is not None
            watch = node._late_watch
            if watch is not None and not node._clock.use_sim_time:
                watch.arm(id(self), deadline, self._entity_name)
            try:
                await self._sleep_until(deadline)
            except ClockJump:
                node.get_logger().warning(
                    f"sim time jumped backwards: timer of {self.period_ns / 1e9:g}s restarts its period"
                )
                self._next_ns = self._now() + self.period_ns
                continue
            if self._cancelled or self._restart:
                continue
            now = self._now()
            if now < deadline:
                continue  # woken early by a poke
            group = self.callback_group
            callback = self._callback_for(deadline)
            if group.exclusive:
                await node._invoke(self, group, callback, start_deadline=deadline)
            else:
                node._create_task(
                    node._invoke(self, group, callback, start_deadline=deadline),
                    name="timer callback",
                )
            # Next deadline on the grid; skip the ones the callback overran.
            now = self._now()
            nxt = deadline + self.period_ns
            if now >= nxt:
                missed = (now - deadline) // self.period_ns
                self._overruns += missed
                nxt = deadline + (missed + 1) * self.period_ns
            if not self._restart:
                self._next_ns = nxt

    def _record_start(self, deadline_ns: int) -> None:
        now = self._now()
        self._last_call_ns = now
        late = now - deadline_ns
        if late < 0:
            late = 0
        self._calls += 1
        self._lateness.append(late)
        if late > self._max_late:
            self._max_late = late
        watch = self.node._late_watch
        if watch is not None:
            watch.fired(id(self), deadline_ns, late)

    def destroy(self) -> None:
        self.node.destroy_timer(self)


class Rate:
    """``await rate.sleep()`` keeps a loop at ``frequency`` Hz on absolute deadlines (node clock)."""

    def __init__(self, node: Node, frequency: float) -> None:
        if isinstance(frequency, bool) or not isinstance(frequency, (int, float)) or not frequency > 0:
            raise ValueError(f"rate: expected a frequency in Hz > 0, got {frequency!r}")
        self.node = node
        self.period_ns = round(1e9 / frequency)
        self.destroyed = False
        self._sleepers: set[asyncio.Future[None]] = set()
        # The grid starts at creation, as ROS's Rate; a node not yet running starts it at the first sleep.
        self._next_ns: int | None = self._now() + self.period_ns if node._loop is not None else None

    def __repr__(self) -> str:
        return f"<Rate {1e9 / self.period_ns:g} Hz of {self.node.get_fully_qualified_name()}>"

    def _now(self) -> int:
        clock = self.node._clock
        return clock.now_ns() if clock.use_sim_time else time.monotonic_ns()

    def destroy(self) -> None:
        """Retire the rate (``Node.destroy_rate``), from any thread.

        A task sleeping on it wakes and its ``sleep()`` returns, as rclpy's ``Rate.destroy``
        wakes its sleepers; a later ``sleep()`` raises ``RuntimeError``.
        """
        self.destroyed = True
        sleepers, self._sleepers = self._sleepers, set()
        for fut in sleepers:
            post(fut.get_loop(), wake, fut)

    async def sleep(self) -> None:
        if self.destroyed:
            raise RuntimeError(f"{self!r} was destroyed")
        now = self._now()
        if self._next_ns is None:
            self._next_ns = now + self.period_ns
        elif now >= self._next_ns + self.period_ns:
            self._next_ns = now + self.period_ns  # fell behind: restart instead of bursting
        deadline = self._next_ns
        self._next_ns += self.period_ns
        clock = self.node._clock
        # One future, resolved by whichever comes first: the deadline or destroy()
        fut: asyncio.Future[None] = asyncio.get_running_loop().create_future()
        try:
            if clock.use_sim_time:
                clock.add_waiter(deadline, fut)
            else:
                waker = self.node._waker
                if waker is None:
                    raise RuntimeError(f"{self!r}: the node is not added to a runtime")
                waker.add(deadline, fut)
            self._sleepers.add(fut)
            if self.destroyed:  # destroy() ran in another thread before the add
                wake(fut)
            try:
                await fut
            finally:
                self._sleepers.discard(fut)
        except ClockJump:
            self._next_ns = None
