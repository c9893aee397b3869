"""Driving sim time: a ``/clock`` publisher node that tests and simulators step."""

from __future__ import annotations

from .._core._clock_publisher import ClockPublisher
from .._core._runtime import Runtime
from .._core._time import Duration

__all__ = ["ClockPublisher", "SimClock"]


class SimClock:
    """Steps ``/clock`` of a ``Runtime(use_sim_time=True)`` so timers fire without wall-clock waits.

    ``await sim.advance(0.5)`` moves time forward in ``step_sec`` increments and lets
    every callback that became due run before returning. ``await sim.set(t)`` jumps
    (backwards too, which restarts timers as in ROS 2).
    """

    def __init__(self, runtime: Runtime, *, start_sec: float = 0.0, step_sec: float = 0.001) -> None:
        if not runtime.use_sim_time:
            raise ValueError("SimClock needs a Runtime(use_sim_time=True)")
        self.runtime = runtime
        self.step_ns = Duration(seconds=step_sec).nanoseconds
        self._node = ClockPublisher(name=f"sim_clock_{id(self):x}")
        runtime.add_node(self._node)
        self._start_ns = Duration(seconds=start_sec).nanoseconds

    def __repr__(self) -> str:
        return f"<SimClock t={self.now_ns / 1e9:g}s step={self.step_ns / 1e9:g}s>"

    @property
    def now_ns(self) -> int:
        return self._node.time_ns

    async def start(self) -> None:
        """Publish the start time (the clock reads zero until the first ``/clock``)."""
        await self.set(self._start_ns / 1e9)

    async def set(self, seconds: float) -> None:
        self._node.publish_time(Duration(seconds=seconds).nanoseconds)
        await self.runtime.settle()

    async def advance(self, seconds: float, *, step_sec: float | None = None) -> None:
        step = self.step_ns if step_sec is None else Duration(seconds=step_sec).nanoseconds
        if step <= 0:
            raise ValueError(f"step_sec: expected > 0, got {step_sec!r}")
        target = self.now_ns + Duration(seconds=seconds).nanoseconds
        t = self.now_ns
        while t < target:
            t = min(t + step, target)
            self._node.publish_time(t)
            await self.runtime.settle()
