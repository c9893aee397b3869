"""Clocks: system time, steady time, and ROS time that follows ``/clock`` under sim time.

A :class:`Clock` is shared by every node of a runtime, on both loops, so its sim
state is guarded by a lock and its waiters are woken on their own loop with
``call_soon_threadsafe``.
"""

from __future__ import annotations

import asyncio
import enum
import heapq
import itertools
import threading
import time
from collections.abc import Callable, Coroutine
from dataclasses import dataclass
from typing import Any

from ._handoff import call_on, wake
from ._time import ClockType, Duration, Time

__all__ = ["Clock", "ClockChange", "ClockJump", "JumpHandle", "JumpThreshold", "ROSClock", "TimeJump"]


class ClockChange(enum.IntEnum):
    """What happened to the clock in a :class:`TimeJump` (as rcl's ``rcl_clock_change_t``)."""

    ROS_TIME_NO_CHANGE = 1
    ROS_TIME_ACTIVATED = 2
    ROS_TIME_DEACTIVATED = 3
    SYSTEM_TIME_NO_CHANGE = 4


class JumpThreshold:
    """When a jump callback fires: a forward jump of at least ``min_forward``, a backward jump of
    at least ``-min_backward`` (a negative duration), and/or ROS time switching on or off."""

    def __init__(
        self, *, min_forward: Duration | None, min_backward: Duration | None, on_clock_change: bool = True
    ) -> None:
        if min_forward is not None and min_forward.nanoseconds <= 0:
            raise ValueError(f"min_forward must be a positive non-zero duration, found {min_forward!r}")
        if min_backward is not None and min_backward.nanoseconds >= 0:
            raise ValueError(f"min_backward must be a negative non-zero duration, found {min_backward!r}")
        if min_forward is None and min_backward is None and not on_clock_change:
            raise ValueError("at least one jump threshold must be enabled")
        self.min_forward = min_forward
        self.min_backward = min_backward
        self.on_clock_change = on_clock_change

    def __repr__(self) -> str:
        return (
            f"JumpThreshold(min_forward={self.min_forward!r}, min_backward={self.min_backward!r}, "
            f"on_clock_change={self.on_clock_change})"
        )

    def exceeded(self, change: ClockChange, delta_ns: int) -> bool:
        """Whether a jump of ``delta_ns`` (with ``change``) crosses this threshold (rcl's rule)."""
        if change in (ClockChange.ROS_TIME_ACTIVATED, ClockChange.ROS_TIME_DEACTIVATED):
            return self.on_clock_change
        if delta_ns > 0:
            return self.min_forward is not None and delta_ns >= self.min_forward.nanoseconds
        if delta_ns < 0:
            return self.min_backward is not None and delta_ns <= self.min_backward.nanoseconds
        return False


@dataclass(frozen=True, slots=True)
class TimeJump:
    """What a post-jump callback receives: the kind of change and how far time moved."""

    clock_change: ClockChange
    delta: Duration


class JumpHandle:
    """A registered jump callback; ``unregister()`` (or leaving ``with handle:``) removes it."""

    def __init__(
        self,
        clock: Clock,
        threshold: JumpThreshold,
        pre_callback: Callable[[], Any] | None,
        post_callback: Callable[[TimeJump], Any] | None,
    ) -> None:
        if pre_callback is None and post_callback is None:
            raise ValueError("one of pre_callback or post_callback must be given")
        for what, cb in (("pre_callback", pre_callback), ("post_callback", post_callback)):
            if cb is not None and not callable(cb):
                raise ValueError(f"{what} must be callable if given, found {cb!r}")
        self._clock: Clock | None = clock
        self.threshold = threshold
        self.pre_callback = pre_callback
        self.post_callback = post_callback

    def unregister(self) -> None:
        if self._clock is not None:
            self._clock._remove_jump_handle(self)
            self._clock = None

    def __enter__(self) -> JumpHandle:
        return self

    def __exit__(self, *exc: object) -> None:
        self.unregister()


class ClockJump(Exception):
    """Raised into a sim-time waiter when time jumps backwards (``/clock`` was reset)."""


class Clock:
    """A clock as in rclpy: ``now()``, and for ROS time an optional sim-time override.

    With ``use_sim_time`` the clock reads zero until the first ``/clock`` message,
    then follows it; waiters (timers, rates, timeouts) wake when sim time reaches
    their deadline, and get :class:`ClockJump` when it jumps backwards.

    rclpy difference: ``Clock()`` is a ROS_TIME clock (rclpy's default is SYSTEM_TIME),
    and ``ROSClock`` is this class itself rather than a subclass, so every clock has
    ``ros_time_is_active`` and ``set_ros_time_override``.
    """

    def __init__(self, clock_type: ClockType = ClockType.ROS_TIME, *, use_sim_time: bool = False):
        if not isinstance(clock_type, ClockType):
            raise TypeError(f"clock_type: expected a ClockType (e.g. ClockType.STEADY_TIME), found {clock_type!r}")
        if use_sim_time and clock_type is not ClockType.ROS_TIME:
            raise ValueError("only a ROS_TIME clock can follow sim time")
        self.clock_type = clock_type
        self._use_sim_time = use_sim_time
        self._sim_ns = 0
        self._lock = threading.Lock()
        self._waiters: list[tuple[int, int, asyncio.AbstractEventLoop, asyncio.Future[None]]] = []
        self._seq = itertools.count()
        self._jump_callbacks: list[Callable[[int, int], None]] = []
        self._jump_handles: list[JumpHandle] = []
        self._change_waiters: list[tuple[asyncio.AbstractEventLoop, asyncio.Future[None]]] = []
        self.jumps = 0

    def __repr__(self) -> str:
        mode = f" sim={self._sim_ns}ns" if self._use_sim_time else ""
        return f"<Clock {self.clock_type.name}{mode}>"

    @property
    def use_sim_time(self) -> bool:
        return self._use_sim_time

    @property
    def ros_time_is_active(self) -> bool:
        """True while this ROS clock reads the ``/clock`` override (rclpy's ``ROSClock`` name)."""
        return self._use_sim_time

    def _set_ros_time_is_active(self, enabled: bool) -> None:
        """Switch ROS time (``/clock``) on or off at run time, as the ``use_sim_time`` parameter does.

        Jump callbacks with ``on_clock_change`` run; sim-time waiters are woken with
        :class:`ClockJump` (timers restart their period on the new time base) and
        ``sleep_until`` returns ``False``.
        """
        if self.clock_type is not ClockType.ROS_TIME:
            raise RuntimeError(f"{self!r}: only a ROS_TIME clock can switch ROS time on or off")
        enabled = bool(enabled)
        if enabled == self._use_sim_time:
            return
        change = ClockChange.ROS_TIME_ACTIVATED if enabled else ClockChange.ROS_TIME_DEACTIVATED
        wall = time.time_ns()
        delta = self._sim_ns - wall if enabled else wall - self._sim_ns
        handles = self._matching_handles(change, delta)
        _run_pre(handles)
        with self._lock:
            self._use_sim_time = enabled
            due = [(loop, fut) for _, _, loop, fut in self._waiters] + self._change_waiters
            self._waiters.clear()
            self._change_waiters = []
        exc = ClockJump(f"ROS time {'activated' if enabled else 'deactivated'}")
        for loop, fut in due:
            call_on(loop, wake, fut, exc)
        _run_post(handles, TimeJump(change, Duration(nanoseconds=delta)))

    def set_ros_time_override(self, time_: Time) -> None:
        """Set the time this clock reports while ROS time is active (rclpy's ``ROSClock`` method)."""
        if not isinstance(time_, Time):
            raise TypeError(f"expected a Time, found {type(time_).__name__}")
        with self._lock:
            if not self._use_sim_time:  # kept for when ROS time is switched on, as rcl does
                self._sim_ns = time_.nanoseconds
                return
        self.set_sim_time(time_.nanoseconds)

    def create_jump_callback(
        self,
        threshold: JumpThreshold,
        *,
        pre_callback: Callable[[], Any] | None = None,
        post_callback: Callable[[TimeJump], Any] | None = None,
    ) -> JumpHandle:
        """Call ``pre_callback()`` before and ``post_callback(TimeJump)`` after a time jump that
        crosses ``threshold`` (sim time moved by ``/clock``, or ROS time switched on or off).

        Callbacks run on the thread that moves the clock and must not block; keep the
        returned handle and ``unregister()`` it when done.
        """
        if not isinstance(threshold, JumpThreshold):
            raise TypeError(f"threshold: expected a JumpThreshold, found {threshold!r}")
        handle = JumpHandle(self, threshold, pre_callback, post_callback)
        with self._lock:
            self._jump_handles.append(handle)
        return handle

    def _remove_jump_handle(self, handle: JumpHandle) -> None:
        with self._lock:
            if handle in self._jump_handles:
                self._jump_handles.remove(handle)

    def _matching_handles(self, change: ClockChange, delta_ns: int) -> list[JumpHandle]:
        with self._lock:
            handles = list(self._jump_handles)
        return [h for h in handles if h.threshold.exceeded(change, delta_ns)]

    def now_ns(self) -> int:
        if self._use_sim_time:
            return self._sim_ns
        if self.clock_type is ClockType.STEADY_TIME:
            return time.monotonic_ns()
        return time.time_ns()

    def now(self) -> Time:
        return Time(nanoseconds=self.now_ns(), clock_type=self.clock_type)

    # -- sim time -----------------------------------------------------------------

    def set_sim_time(self, nanoseconds: int) -> None:
        """Move sim time (called for every ``/clock`` message); wakes due waiters."""
        if not self._use_sim_time:
            raise RuntimeError(f"{self!r} does not use sim time")
        due: list[tuple[asyncio.AbstractEventLoop, asyncio.Future[None]]] = []
        handles = self._matching_handles(ClockChange.ROS_TIME_NO_CHANGE, nanoseconds - self._sim_ns)
        _run_pre(handles)
        with self._lock:
            previous = self._sim_ns
            self._sim_ns = nanoseconds
            jumped_back = nanoseconds < previous
            if jumped_back:
                self.jumps += 1
                due = [(loop, fut) for _, _, loop, fut in self._waiters]
                self._waiters.clear()
            else:
                while self._waiters and self._waiters[0][0] <= nanoseconds:
                    _, _, loop, fut = heapq.heappop(self._waiters)
                    due.append((loop, fut))
            callbacks = list(self._jump_callbacks) if jumped_back else []
        exc = ClockJump(f"sim time jumped back from {previous} ns to {nanoseconds} ns") if jumped_back else None
        for loop, fut in due:
            call_on(loop, wake, fut, exc)
        for cb in callbacks:
            cb(previous, nanoseconds)
        _run_post(handles, TimeJump(ClockChange.ROS_TIME_NO_CHANGE, Duration(nanoseconds=nanoseconds - previous)))

    def add_jump_callback(self, callback: Callable[[int, int], None]) -> Callable[[], None]:
        """Call ``callback(old_ns, new_ns)`` when sim time jumps backwards; returns a remover."""
        with self._lock:
            self._jump_callbacks.append(callback)

        def remove() -> None:
            with self._lock:
                if callback in self._jump_callbacks:
                    self._jump_callbacks.remove(callback)

        return remove

    def add_waiter(self, deadline_ns: int, fut: asyncio.Future[None]) -> None:
        """Resolve ``fut`` (on its own loop) when sim time reaches ``deadline_ns``.

        Sets :class:`ClockJump` on it if sim time jumps backwards first. A future
        finished by someone else is dropped when its time comes.
        """
        if not self._use_sim_time:
            raise RuntimeError(f"{self!r} does not use sim time; wall-time waits use a waker")
        loop = fut.get_loop()
        with self._lock:
            if self._sim_ns >= deadline_ns:
                fut.set_result(None)
                return
            heapq.heappush(self._waiters, (deadline_ns, next(self._seq), loop, fut))

    def next_deadline_ns(self) -> int | None:
        """The earliest sim-time deadline anyone waits for (a timer, a rate, a timeout), or None.

        A simulator that owns time steps to it so every timer fires exactly on its deadline.
        """
        with self._lock:
            while self._waiters and self._waiters[0][3].done():
                heapq.heappop(self._waiters)
            return self._waiters[0][0] if self._waiters else None

    async def sleep_until_ns(self, deadline_ns: int) -> None:
        """Wait until sim time reads ``deadline_ns``; raises :class:`ClockJump` on a backwards jump."""
        fut: asyncio.Future[None] = asyncio.get_running_loop().create_future()
        self.add_waiter(deadline_ns, fut)
        await fut

    async def sleep_for(self, rel_time: Duration | float) -> bool:
        """Sleep on this clock for ``rel_time`` (a Duration or seconds): ``sleep_until(now + rel_time)``.

        rclpy difference: a coroutine (rclpy's blocks the thread), and it also takes seconds.
        """
        ns = rel_time.nanoseconds if isinstance(rel_time, Duration) else round(rel_time * 1e9)
        return await self.sleep_until(Time(nanoseconds=self.now_ns() + ns, clock_type=self.clock_type))

    def sleep_until(self, until: Time) -> Coroutine[Any, Any, bool]:
        """Sleep until this clock reads ``until``: ``await clock.sleep_until(t)``.

        Returns ``True`` when it was reached, ``False`` when ROS time was switched on or
        off meanwhile (the epoch changed, so the wait lost its meaning), as rclpy. Sim
        time jumping backwards keeps the wait going. Raises ``ValueError`` for a time of
        another clock type ("clock type does not match", rclpy's words) at the call, before
        anything is awaited.

        rclpy difference: a coroutine (rclpy's blocks the thread); cancelling the task is
        how a shutdown wakes it, so there is no ``context`` argument.
        """
        if not isinstance(until, Time):
            raise TypeError(f"until: expected a Time, found {type(until).__name__}")
        if until.clock_type is not self.clock_type:
            raise ValueError(
                f"sleep_until: clock type does not match: until is {until.clock_type.name}, "
                f"this clock is {self.clock_type.name}"
            )
        return self._sleep_until(until)

    async def _sleep_until(self, until: Time) -> bool:
        loop = asyncio.get_running_loop()
        changed: asyncio.Future[None] = loop.create_future()
        with self._lock:
            self._change_waiters.append((loop, changed))
        try:
            while True:
                if changed.done():
                    return False
                if self.now_ns() >= until.nanoseconds:
                    return True
                if self._use_sim_time:
                    alarm: asyncio.Future[None] = loop.create_future()
                    try:
                        self.add_waiter(until.nanoseconds, alarm)
                        await alarm
                    except (ClockJump, RuntimeError):
                        continue  # backwards /clock, or the mode changed (``changed`` says which)
                else:
                    remaining = (until.nanoseconds - self.now_ns()) / 1e9
                    await asyncio.wait((changed,), timeout=max(remaining, 0.0))
        finally:
            with self._lock:
                if (loop, changed) in self._change_waiters:
                    self._change_waiters.remove((loop, changed))
            if not changed.done():
                changed.cancel()
            elif not changed.cancelled():
                changed.exception()  # retrieved: no "never retrieved" warning


def _run_pre(handles: list[JumpHandle]) -> None:
    for handle in handles:
        if handle.pre_callback is not None:
            handle.pre_callback()


def _run_post(handles: list[JumpHandle], jump: TimeJump) -> None:
    for handle in handles:
        if handle.post_callback is not None:
            handle.post_callback(jump)


#: rclpy's name for the ROS-time clock; here every ROS_TIME ``Clock`` is one.
ROSClock = Clock
