"""The culprit of late priority periods: the function that held the GIL (another thread, or the
main loop's callback) is named as the top cause of lateness."""

from __future__ import annotations

import threading
import time

from aiorobot import Node, Runtime
from aiorobot._core._culprit import Culprit

from tests.transport._helpers import wait_until

HOLD_SEC = 0.004  # each GIL-holding C call: four times the default late_threshold


def _calibrated_n() -> int:
    """N for which ``sum(range(N))`` (one C call holding the GIL) takes about HOLD_SEC here."""
    n = 100_000
    start = time.perf_counter()
    sum(range(n))
    took = max(time.perf_counter() - start, 1e-6)
    return max(10_000, int(n * HOLD_SEC / took))


def _control_node() -> Node:
    control = Node("control")
    control.create_timer(0.01, lambda: None)
    return control


def _attributed(rt: Runtime, periods: int) -> bool:
    culprits = rt.statistics()["culprits"]
    return sum(c.late_periods for c in culprits if not c.function.startswith("(")) >= periods


def _top_named(culprits: list[Culprit]) -> Culprit:
    """The top culprit that is a function: on a loaded machine the OS also makes periods late, which
    the report shows as ``(no Python thread)`` beside the functions (it names no one)."""
    named = [c for c in culprits if not c.function.startswith("(")]
    assert named, [c.describe() for c in culprits]
    return named[0]


async def test_a_thread_making_long_gil_holding_calls_is_named_top_cause() -> None:
    n = _calibrated_n()
    stop = threading.Event()

    def crunch_in_thread() -> None:
        while not stop.is_set():
            sum(range(n))
            time.sleep(0.003)

    worker = threading.Thread(target=crunch_in_thread, name="cruncher")
    async with Runtime(handle_signals=False) as rt:
        rt.add_node(_control_node(), "priority")
        worker.start()
        try:
            await wait_until(lambda: _attributed(rt, 12), timeout_sec=30)
        finally:
            stop.set()
            worker.join()
        stats = rt.statistics()
    top = _top_named(stats["culprits"])
    assert top.function.endswith("crunch_in_thread") and top.thread == "cruncher", [c.describe() for c in stats["culprits"]]
    assert top.where.startswith("test_culprit.py:") and top.node == ""
    assert stats["late_periods"] >= top.late_periods >= 6 and top.lateness_total_sec > 0.006


async def test_perception_holding_the_gil_inline_on_the_main_loop_is_named_with_its_node() -> None:
    n = _calibrated_n()

    class Perception(Node):
        def __init__(self) -> None:
            super().__init__("perception")
            self.create_timer(0.007, self.perceive)

        def perceive(self) -> None:
            sum(range(n))  # stands for a numpy operation that keeps the GIL

    async with Runtime(handle_signals=False) as rt:
        rt.add_node(_control_node(), "priority")
        rt.add_node(Perception())
        await wait_until(lambda: _attributed(rt, 12), timeout_sec=30)
        culprits = rt.statistics()["culprits"]
    top = _top_named(culprits)
    assert top.function.endswith("Perception.perceive"), [c.describe() for c in culprits]
    assert (top.node, top.entity, top.thread) == ("/perception", "timer 0.007s", "main loop")


async def test_nothing_is_late_on_an_idle_runtime_and_the_watch_stops_with_it() -> None:
    async with Runtime(handle_signals=False, late_threshold=0.5) as rt:
        control = rt.add_node(_control_node(), "priority")
        await wait_until(lambda: control.timers[0].statistics().calls >= 10)
        watch = rt.late_watch
        assert watch is not None and watch.threshold_ns == 500_000_000
        assert rt.statistics()["late_periods"] == 0 and rt.statistics()["culprits"] == []
    assert watch._closed  # closed with the runtime; its figures stay readable
