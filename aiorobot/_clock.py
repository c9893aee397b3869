"""Clocks: system time, steady time, and ROS time that follows ``/clock`` under sim time.

A :class:`Clock` is shared by every node of a runtime, on both loops, so its sim
state is guarded by a lock and its waiters are woken on their own loop with
``call_soon_threadsafe``.
"""

from __future__ import annotations

import asyncio
import heapq
import itertools
import threading
import time
from collections.abc import Callable

from ._time import ClockType, Duration, Time

__all__ = ["Clock", "ClockJump"]


class ClockJump(Exception):
    """Raised into a sim-time waiter when time jumps backwards (``/clock`` was reset)."""


def _wake(fut: asyncio.Future[None], exc: BaseException | None) -> None:
    if not fut.done():
        if exc is None:
            fut.set_result(None)
        else:
            fut.set_exception(exc)


class Clock:
    """A clock as in rclpy: ``now()``, and for ROS time an optional sim-time override.

    With ``use_sim_time`` the clock reads zero until the first ``/clock`` message,
    then follows it; waiters (timers, rates, timeouts) wake when sim time reaches
    their deadline, and get :class:`ClockJump` when it jumps backwards.
    """

    def __init__(self, clock_type: ClockType = ClockType.ROS_TIME, *, use_sim_time: bool = False):
        if use_sim_time and clock_type is not ClockType.ROS_TIME:
            raise ValueError("only a ROS_TIME clock can follow sim time")
        self.clock_type = clock_type
        self._use_sim_time = use_sim_time
        self._sim_ns = 0
        self._lock = threading.Lock()
        self._waiters: list[tuple[int, int, asyncio.AbstractEventLoop, asyncio.Future[None]]] = []
        self._seq = itertools.count()
        self._jump_callbacks: list[Callable[[int, int], None]] = []
        self.jumps = 0

    def __repr__(self) -> str:
        mode = f" sim={self._sim_ns}ns" if self._use_sim_time else ""
        return f"<Clock {self.clock_type.name}{mode}>"

    @property
    def use_sim_time(self) -> bool:
        return self._use_sim_time

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
            _call_on(loop, _wake, fut, exc)
        for cb in callbacks:
            cb(previous, nanoseconds)

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

    async def sleep_for(self, duration: Duration | float) -> None:
        """Sleep on this clock: sim time when it follows ``/clock``, else wall time."""
        ns = duration.nanoseconds if isinstance(duration, Duration) else round(duration * 1e9)
        if self._use_sim_time:
            await self.sleep_until_ns(self._sim_ns + ns)
        else:
            await asyncio.sleep(ns / 1e9)


def _call_on(loop: asyncio.AbstractEventLoop, fn: Callable[..., object], *args: object) -> None:
    """Run ``fn(*args)`` on ``loop``: now if we are on it, else through call_soon_threadsafe."""
    try:
        running = asyncio.get_running_loop()
    except RuntimeError:
        running = None
    if running is loop:
        fn(*args)
    elif not loop.is_closed():
        loop.call_soon_threadsafe(fn, *args)
