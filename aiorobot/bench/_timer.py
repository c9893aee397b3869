"""Part ``timer``: precision of a 1 kHz timer on the priority loop.

A node with a 1 ms timer runs on the priority loop for ``duration_sec`` (5 s;
quick: 0.3 s), with ``Runtime()`` and with ``Runtime(priority_realtime=True)``
(SCHED_FIFO where permitted), each once with the main loop idle and once while
the main loop is busy with pure-Python work (1 ms slices back to back, yielding to the loop
between slices: it holds the GIL nearly all the time, like a loaded
application). Reported: the period error (|period - 1 ms|) p50/p99/max, the
timer's own lateness figures (``Timer.stats``) and the CPU the priority thread
used (``time.thread_time`` read inside it) as a share of one core.
"""

from __future__ import annotations

import asyncio
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


def run(quick: bool = False) -> dict[str, Any]:
    """Run both rows; returns ``{"rows": [...], "noise": {...}}``."""
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
    assert part_meter.result is not None
    return {"period_ms": PERIOD_SEC * 1e3, "duration_sec": duration, "rows": rows, "noise": part_meter.result.as_dict()}
