"""Timers on sim time: absolute deadlines, skipping overruns, cancel/reset, statistics, jumps."""

import asyncio
import logging

import pytest

from aiorobot import MutuallyExclusiveCallbackGroup, Node, ReentrantCallbackGroup
from aiorobot._core._timer import _percentile


class Ticker(Node):
    def __init__(self, period_sec=0.1, **kw):
        super().__init__("ticker", **kw)
        self.ticks = []
        self.timer = self.create_timer(period_sec, self.tick)

    def tick(self):
        self.ticks.append(self.now().nanoseconds)


async def test_timer_fires_on_sim_time_deadlines(sim_runtime, sim_clock):
    node = sim_runtime.add_node(Ticker(0.1))
    await sim_clock.advance(0.55)
    start = 1_000_000_000
    assert node.ticks == [start + k * 100_000_000 for k in range(1, 6)]


async def test_timer_does_not_drift_under_uneven_steps(sim_runtime, sim_clock):
    node = sim_runtime.add_node(Ticker(0.1))
    clock_values = []
    for step in [0.013, 0.07, 0.031, 0.047, 0.029, 0.061, 0.083, 0.017] * 4:
        await sim_clock.advance(step, step_sec=step)
        clock_values.append(sim_clock.now_ns)
    # Deadline k is 1 s + k * 100 ms whatever the steps: each fires at the first clock value reaching it.
    deadlines = range(1_100_000_000, clock_values[-1] + 1, 100_000_000)
    expected = [next(t for t in clock_values if t >= d) for d in deadlines]
    assert node.ticks == expected
    assert node.timer.stats.calls == len(expected) and node.timer.stats.overruns == 0


async def test_paused_clock_pauses_timers(sim_runtime, sim_clock):
    node = sim_runtime.add_node(Ticker(0.1))
    await sim_clock.advance(0.25)
    calls = len(node.ticks)
    for _ in range(20):  # loops run, /clock does not move
        await asyncio.sleep(0)
    assert len(node.ticks) == calls == 2


async def test_overrun_skips_missed_periods_instead_of_bursting(sim_runtime, sim_clock):
    node = sim_runtime.add_node(Ticker(0.1))
    await sim_clock.advance(0.1)
    assert len(node.ticks) == 1
    await sim_clock.advance(0.35, step_sec=0.35)  # one jump over three deadlines
    assert len(node.ticks) == 2  # fired once, not three times
    stats = node.timer.stats
    assert stats.overruns == 2
    await sim_clock.advance(0.05)  # next deadline stays on the grid: 1.5 s
    assert node.ticks[-1] == 1_500_000_000


async def test_cancel_stops_and_reset_restarts_from_now(sim_runtime, sim_clock):
    node = sim_runtime.add_node(Ticker(0.1))
    await sim_clock.advance(0.1)
    node.timer.cancel()
    assert node.timer.is_canceled()
    await sim_clock.advance(0.5)
    assert len(node.ticks) == 1
    await sim_clock.advance(0.025)  # now 1.625 s
    node.timer.reset()
    await sim_clock.advance(0.1)
    assert node.ticks[-1] == 1_725_000_000


async def test_backward_jump_restarts_timers_with_a_warning(sim_runtime, sim_clock, caplog):
    node = sim_runtime.add_node(Ticker(0.1))
    await sim_clock.advance(0.2)
    with caplog.at_level(logging.WARNING):
        await sim_clock.set(0.5)
    assert "jumped backwards" in caplog.text
    await sim_clock.advance(0.1)
    assert node.ticks[-1] == 600_000_000


async def test_statistics_record_calls_and_lateness(sim_runtime, sim_clock):
    node = sim_runtime.add_node(Ticker(0.1))
    await sim_clock.advance(0.3)
    stats = node.timer.statistics()
    assert stats.calls == 3 and stats.overruns == 0 and stats.period_sec == 0.1
    assert stats.lateness_p50_sec == 0.0 and stats.lateness_max_sec == 0.0


def test_percentile_interpolates_like_numpy():
    import numpy as np

    values = [5, 1, 9, 3, 7, 2]
    for q in (0.0, 0.5, 0.99, 1.0):
        assert _percentile(sorted(values), q) == round(np.percentile(values, q * 100))


async def test_exclusive_timer_waits_for_the_group_lock(sim_runtime, sim_clock):
    group = MutuallyExclusiveCallbackGroup()
    node = sim_runtime.add_node(Node("n"))
    release = asyncio.Event()
    order = []

    async def holder():
        order.append("holder start")
        await release.wait()
        order.append("holder end")

    node.create_timer(0.1, holder, callback_group=group)
    node.create_timer(0.1, lambda: order.append("other"), callback_group=group)
    await sim_clock.advance(0.1)
    assert order == ["holder start"]
    release.set()
    await sim_clock.advance(0.001)
    assert order[:3] == ["holder start", "holder end", "other"]


async def test_reentrant_timer_overlaps_with_itself(sim_runtime, sim_clock):
    node = sim_runtime.add_node(Node("n"))
    release = asyncio.Event()
    running = []

    async def slow():
        running.append(1)
        await release.wait()

    node.create_timer(0.1, slow, callback_group=ReentrantCallbackGroup())
    await sim_clock.advance(0.3)
    assert len(running) == 3  # three invocations in flight together
    release.set()


async def test_timer_rejects_a_non_positive_period():
    with pytest.raises(ValueError, match="period"):
        Node("n").create_timer(0, print)


async def test_wall_clock_timer_fires_and_keeps_its_grid(runtime):
    fired = asyncio.Event()
    node = runtime.add_node(Node("n"))
    calls = []

    def tick():
        calls.append(1)
        if len(calls) == 3:
            fired.set()

    timer = node.create_timer(0.005, tick)
    async with asyncio.timeout(30):  # generous: shared machines stall
        await fired.wait()
    assert timer.stats.calls >= 3


async def test_rate_sleeps_on_sim_time(sim_runtime, sim_clock):
    node = sim_runtime.add_node(Node("n"))
    rate = node.create_rate(10)
    stamps = []

    async def loop():
        for _ in range(3):
            await rate.sleep()
            stamps.append(node.now().nanoseconds)

    task = asyncio.create_task(loop())
    await sim_clock.advance(0.35)
    await task
    assert stamps == [1_100_000_000, 1_200_000_000, 1_300_000_000]


async def test_priority_loop_timer_follows_sim_time(sim_runtime, sim_clock):
    node = sim_runtime.add_node(Ticker(0.1), executor="priority")
    await sim_clock.advance(0.35)
    assert node.ticks == [1_100_000_000, 1_200_000_000, 1_300_000_000]
    await sim_clock.set(0.5)  # a backwards jump reaches the other thread's timer too
    await sim_clock.advance(0.1)
    assert node.ticks[-1] == 600_000_000
