"""Executor model ``single``: one asyncio loop, perception inline.

The analogue of rclpy's ``SingleThreadedExecutor``: both timers live on one
loop and the perception callback runs its 150 ms of work right there, so the
control timer waits behind it. Timers follow rcl's rules: absolute deadlines,
the next deadline is set when the callback is taken, and missed periods are
skipped rather than replayed.
"""

from __future__ import annotations

import asyncio
import math
import time
from collections.abc import Callable

from ._seedconfig import SeedConfig
from ._workload import work_function

__all__ = ["new_event_loop", "run_single"]


def new_event_loop() -> asyncio.AbstractEventLoop:
    """A uvloop loop where uvloop is installed (as ``aiorobot.run`` uses), else asyncio's."""
    try:
        import uvloop
    except ImportError:  # pragma: no cover - uvloop is a dependency off Windows
        return asyncio.new_event_loop()
    return uvloop.new_event_loop()


def next_deadline(deadline: float, period: float, now: float) -> float:
    """rcl's timer rule: advance by one period, skipping whole periods already missed."""
    deadline += period
    if deadline < now:
        deadline += math.ceil((now - deadline) / period) * period
    return deadline


class _Timer:
    def __init__(self, period_sec: float, callback: Callable[[], None]) -> None:
        self.period_sec = period_sec
        self.callback = callback
        self.deadline = time.perf_counter() + period_sec


async def _spin(timers: list[_Timer], stop: asyncio.Event) -> None:
    """rclpy's ``SingleThreadedExecutor.spin`` for timers, on an asyncio loop.

    Wait until the earliest deadline, then run every ready timer in creation
    order (rclpy yields the ready handlers of one wait in that order), then wait
    again.
    """
    while not stop.is_set():
        now = time.perf_counter()
        ready = [t for t in timers if t.deadline <= now]
        if not ready:
            await asyncio.sleep(min(t.deadline for t in timers) - now)
            continue  # loop timers count whole milliseconds and may wake early: re-check
        for timer in ready:
            if stop.is_set():
                break
            timer.deadline = next_deadline(timer.deadline, timer.period_sec, time.perf_counter())
            timer.callback()


async def _run(kind: str, cfg: SeedConfig) -> list[float]:
    work = work_function(kind)
    stamps: list[float] = []
    stop = asyncio.Event()

    def control() -> None:
        stamps.append(time.perf_counter())
        if len(stamps) >= cfg.stamps_needed:
            stop.set()

    def perception() -> None:
        work(cfg.work_sec)

    await _spin([_Timer(cfg.control_period_sec, control), _Timer(cfg.perception_period_sec, perception)], stop)
    return stamps


def run_single(kind: str, cfg: SeedConfig) -> list[float]:
    """Run the model; returns the control callback's start stamps in seconds."""
    loop = new_event_loop()
    try:
        return loop.run_until_complete(_run(kind, cfg))
    finally:
        loop.close()
