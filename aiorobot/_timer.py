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
import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from ._clock import ClockJump

if TYPE_CHECKING:
    from ._groups import CallbackGroup
    from ._node import Node

__all__ = ["Rate", "Timer", "TimerStatistics"]

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
    """Calls ``callback`` every ``period_sec``; created by ``Node.create_timer``."""

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
        self.callback_group = group
        self._task: asyncio.Task[None] | None = None
        self._cancelled = not autostart
        self._calls = 0
        self._overruns = 0
        self._lateness: deque[int] = deque(maxlen=_WINDOW)
        self._max_late = 0
        self._next_ns: int | None = None
        self._restart = False
        self._wake: asyncio.Future[None] | None = None
        self.destroyed = False

    def __repr__(self) -> str:
        state = "cancelled" if self._cancelled else "running"
        return f"<Timer {self.period_ns / 1e9:g}s {state} calls={self._calls} of {self.node.get_fully_qualified_name()}>"

    @property
    def timer_period_ns(self) -> int:
        return self.period_ns

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
            if group.exclusive:
                await node._invoke(self, group, self.callback, start_deadline=deadline)
            else:
                node._create_task(
                    node._invoke(self, group, self.callback, start_deadline=deadline),
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
        late = self._now() - deadline_ns
        if late < 0:
            late = 0
        self._calls += 1
        self._lateness.append(late)
        if late > self._max_late:
            self._max_late = late

    def destroy(self) -> None:
        self.node.destroy_timer(self)


class Rate:
    """``await rate.sleep()`` keeps a loop at ``frequency`` Hz on absolute deadlines (node clock)."""

    def __init__(self, node: Node, frequency: float) -> None:
        if isinstance(frequency, bool) or not isinstance(frequency, (int, float)) or not frequency > 0:
            raise ValueError(f"rate: expected a frequency in Hz > 0, got {frequency!r}")
        self.node = node
        self.period_ns = round(1e9 / frequency)
        # The grid starts at creation, as ROS's Rate; a node not yet running starts it at the first sleep.
        self._next_ns: int | None = self._now() + self.period_ns if node._loop is not None else None

    def __repr__(self) -> str:
        return f"<Rate {1e9 / self.period_ns:g} Hz of {self.node.get_fully_qualified_name()}>"

    def _now(self) -> int:
        clock = self.node._clock
        return clock.now_ns() if clock.use_sim_time else time.monotonic_ns()

    async def sleep(self) -> None:
        now = self._now()
        if self._next_ns is None:
            self._next_ns = now + self.period_ns
        elif now >= self._next_ns + self.period_ns:
            self._next_ns = now + self.period_ns  # fell behind: restart instead of bursting
        deadline = self._next_ns
        self._next_ns += self.period_ns
        clock = self.node._clock
        try:
            if clock.use_sim_time:
                await clock.sleep_until_ns(deadline)
            else:
                waker = self.node._waker
                if waker is None:
                    raise RuntimeError(f"{self!r}: the node is not added to a runtime")
                await waker.wait_until_ns(deadline)
        except ClockJump:
            self._next_ns = None
