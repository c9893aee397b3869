"""Part ``timer``: precision of a 1 kHz timer on the priority loop.

A node with a 1 ms timer runs on the priority loop for ``duration_sec`` (5 s;
quick: 0.3 s), with ``Runtime()`` and with ``Runtime(priority_realtime=True)``
(SCHED_FIFO where permitted), each once with the main loop idle and once while
the main loop is busy with pure-Python work (1 ms slices back to back, yielding to the loop
between slices: it holds the GIL nearly all the time, like a loaded
application). Reported: the period error (|period - 1 ms|) p50/p99/max, the
timer's own lateness figures (``Timer.stats``) and the CPU the priority thread
used (``time.thread_time`` read inside it) as a share of one core.

Beside them, the machine's floor: a bare Python thread sleeping to the same
absolute deadlines with ``clock_nanosleep`` (no event loop, no runtime), under
SCHED_OTHER and SCHED_FIFO. No timer on the priority loop can beat it, so its
maximum tells how much of a maximum is the machine's.
"""

from __future__ import annotations

import asyncio
import ctypes
import ctypes.util
import os
import sys
import threading
import time
from collections.abc import Callable
from typing import Any

from ._noise import NoiseMeter
from ._stats import latency_stats, periods_from_stamps
from ._workload import python_chunk

__all__ = ["PERIOD_SEC", "run"]

PERIOD_SEC = 0.001
_WARMUP = 20


async def _measure(duration_sec: float, busy_main: bool, realtime: bool = False) -> dict[str, Any]:
    from aiorobot import Node, Runtime

    n_ticks = _WARMUP + round(duration_sec / PERIOD_SEC) + 1

    class Ticker(Node):
        def __init__(self, done: Callable[[], None]) -> None:
            super().__init__("ticker")
            self.done = done
            self.stamps: list[float] = []
            self.cpu_sec = [0.0, 0.0]
            self.timer = self.create_timer(PERIOD_SEC, self.tick)

        def tick(self) -> None:
            now = time.perf_counter()
            self.stamps.append(now)
            n = len(self.stamps)
            if n == _WARMUP + 1:
                self.cpu_sec[0] = time.thread_time()
            elif n == n_ticks:
                self.cpu_sec[1] = time.thread_time()
                self.timer.cancel()
                self.done()

    class Busy(Node):
        async def on_start(self) -> None:
            while True:
                python_chunk(0.001)
                await asyncio.sleep(0)

    async with Runtime(handle_signals=False, priority_realtime=realtime) as rt:
        ticker = Ticker(rt.shutdown)
        rt.add_node(ticker, executor="priority")
        if busy_main:
            rt.add_node(Busy("busy"))
        applied = list(rt.priority_loop.applied) if rt.priority_loop is not None else []
        await rt.spin()
        stats = ticker.timer.stats
    stamps = ticker.stamps[:n_ticks]
    periods_ms = periods_from_stamps(stamps, _WARMUP)
    wall = stamps[-1] - stamps[_WARMUP]
    errors_us = [abs(p - PERIOD_SEC * 1e3) * 1e3 for p in periods_ms]
    return {
        "runtime": "Runtime(priority_realtime=True)" if realtime else "Runtime()",
        "scheduling": " ".join(applied) or "default",
        "main_loop": "busy (pure Python)" if busy_main else "idle",
        "period_error": latency_stats(errors_us).as_dict(),
        "lateness_us": {
            "p50_us": stats.lateness_p50_sec * 1e6,
            "p99_us": stats.lateness_p99_sec * 1e6,
            "max_us": stats.lateness_max_sec * 1e6,
        },
        "overruns": stats.overruns,
        "thread_cpu_pct": 100.0 * (ticker.cpu_sec[1] - ticker.cpu_sec[0]) / wall,
        "periods_ms": [round(p, 5) for p in periods_ms],
    }


class _Timespec(ctypes.Structure):
    _fields_ = [("tv_sec", ctypes.c_long), ("tv_nsec", ctypes.c_long)]


def _sleeper() -> Callable[[int], None]:
    """A function sleeping until an absolute ``CLOCK_MONOTONIC`` instant (ns), releasing the GIL."""
    if sys.platform.startswith("linux"):
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6", use_errno=True)
        libc.prctl(29, ctypes.c_ulong(1), 0, 0, 0)  # PR_SET_TIMERSLACK: 1 ns, as the priority loop asks

        def sleep_until(deadline_ns: int) -> None:
            sec, nsec = divmod(deadline_ns, 1_000_000_000)
            libc.clock_nanosleep(1, 1, ctypes.byref(_Timespec(sec, nsec)), None)  # CLOCK_MONOTONIC, ABSTIME

        return sleep_until

    def sleep_until_portable(deadline_ns: int) -> None:
        remaining = deadline_ns - time.monotonic_ns()
        if remaining > 0:
            time.sleep(remaining / 1e9)

    return sleep_until_portable


def _floor(duration_sec: float, realtime: bool) -> dict[str, Any]:
    """The machine's floor: a bare thread sleeping to absolute 1 ms deadlines (no loop, no runtime)."""
    n_ticks = _WARMUP + round(duration_sec / PERIOD_SEC) + 1
    period_ns = round(PERIOD_SEC * 1e9)
    stamps: list[float] = []
    lateness_us: list[float] = []
    applied: list[str] = []
    cpu_sec = [0.0]

    def worker() -> None:
        sleep_until = _sleeper()
        if sys.platform.startswith("linux"):
            applied.append("timerslack=1ns")
        if realtime:
            try:
                os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(10))
                applied.append("SCHED_FIFO")
            except (PermissionError, OSError, AttributeError):
                pass
        deadline = time.monotonic_ns() + period_ns
        for i in range(n_ticks):
            sleep_until(deadline)
            now_ns = time.monotonic_ns()
            stamps.append(time.perf_counter())
            if i == _WARMUP:
                cpu_sec[0] = time.thread_time()
            if i > _WARMUP:
                lateness_us.append(max(0, now_ns - deadline) / 1e3)
            deadline += period_ns
            if now_ns >= deadline:  # skip missed deadlines, as the timer does
                deadline += ((now_ns - deadline) // period_ns + 1) * period_ns
        cpu_sec[0] = time.thread_time() - cpu_sec[0]

    thread = threading.Thread(target=worker, name="bench-floor", daemon=True)
    thread.start()
    thread.join()
    periods_ms = periods_from_stamps(stamps, _WARMUP)
    errors_us = [abs(p - PERIOD_SEC * 1e3) * 1e3 for p in periods_ms]
    late = latency_stats(lateness_us)
    return {
        "runtime": "bare thread, clock_nanosleep (floor)",
        "scheduling": " ".join(applied) or "default",
        "main_loop": "idle",
        "period_error": latency_stats(errors_us).as_dict(),
        "lateness_us": {"p50_us": late.p50_us, "p99_us": late.p99_us, "max_us": late.max_us},
        "overruns": sum(1 for p in periods_ms if p >= 2 * PERIOD_SEC * 1e3),
        "thread_cpu_pct": 100.0 * cpu_sec[0] / (stamps[-1] - stamps[_WARMUP]),
        "periods_ms": [round(p, 5) for p in periods_ms],
    }


def run(quick: bool = False) -> dict[str, Any]:
    """Run every row; returns ``{"rows": [...], "noise": {...}}``."""
    import aiorobot

    duration = 0.3 if quick else 5.0
    rows = []
    with NoiseMeter() as part_meter:
        for realtime, busy in ((False, False), (False, True), (True, False), (True, True)):
            with NoiseMeter() as meter:
                row = aiorobot.run(_measure(duration, busy, realtime))
            assert meter.result is not None
            row["noise"] = meter.result.as_dict()
            rows.append(row)
        for realtime in (False, True):
            with NoiseMeter() as meter:
                row = _floor(duration, realtime)
            assert meter.result is not None
            row["noise"] = meter.result.as_dict()
            rows.append(row)
    assert part_meter.result is not None
    return {"period_ms": PERIOD_SEC * 1e3, "duration_sec": duration, "rows": rows, "noise": part_meter.result.as_dict()}
