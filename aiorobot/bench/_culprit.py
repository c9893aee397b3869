"""Part ``culprit``: what the late-period culprit watch costs, and whom it names.

A 50 Hz timer on the priority loop runs for ``duration_sec`` (5 s; quick: 0.3 s):

- with the watch off (``Runtime(late_threshold=None)``) and on (the default 1 ms),
  nothing else running: the process's CPU time over the wall time, as a share of
  one core. The difference is the watch's cost while nothing is late (target <= 1 %).
- with the watch on beside what observing costs: a node logging 100 lines/s (each
  published on ``/rosout``, received by a subscriber as ``aiorobot log`` does) and the
  control node's ``~/get_statistics`` read once a second (as ``aiorobot top`` does): its
  lateness p99 beside the idle row's.
- with the watch on beside a thread making GIL-holding C calls of about 4 ms
  (``sum(range(N))``) with 3 ms pauses: the late periods, and the top culprit the
  runtime names (it should be that thread's function, ``hold_the_gil``).
"""

from __future__ import annotations

import asyncio
import threading
import time
from typing import Any

from ._noise import measure_cases

__all__ = ["run", "table"]

PERIOD_SEC = 0.02
HOLD_SEC = 0.004
CASES = (
    "watch off, idle process",
    "watch on, idle process",
    "watch on, /rosout 100 lines/s, statistics read 1/s",
    "watch on, a thread holding the GIL",
)


def _calibrated_n() -> int:
    n = 200_000
    start = time.perf_counter()
    sum(range(n))
    return max(10_000, int(n * HOLD_SEC / max(time.perf_counter() - start, 1e-6)))


def _observe(rt: Any) -> None:
    """A node logging 100 lines/s onto /rosout with a subscriber, and a reader of ~/get_statistics."""
    import logging

    from aiorobot import Node
    from aiorobot._core._logging import ROSOUT_QOS
    from aiorobot.msgs.rcl_interfaces import Log
    from aiorobot.msgs.std_srvs import Trigger

    talker = rt.add_node(Node("chatty"))
    quiet = logging.getLogger("aiorobot.node.chatty")
    quiet.propagate = False  # its lines reach /rosout, not the bench's terminal
    talker.get_logger().set_level("info")
    talker.create_timer(0.01, lambda: talker.get_logger().info("line"))
    reader = rt.add_node(Node("observer", start_parameter_services=False))
    reader.create_subscription(Log, "/rosout", lambda m: None, ROSOUT_QOS)
    client = reader.create_client(Trigger, "/control/get_statistics")

    async def read() -> None:
        await client.call(Trigger.Request(), timeout_sec=5.0)

    reader.create_timer(1.0, read)


async def _measure(case: str, duration_sec: float) -> dict[str, Any]:
    from aiorobot import Node, Runtime

    stop = threading.Event()
    n = _calibrated_n()

    def hold_the_gil() -> None:
        while not stop.is_set():
            sum(range(n))
            time.sleep(0.003)

    control = Node("control")
    control.create_timer(PERIOD_SEC, lambda: None)
    async with Runtime(handle_signals=False, late_threshold=None if case.startswith("watch off") else 0.001) as rt:
        rt.add_node(control, "priority")
        if "/rosout" in case:
            _observe(rt)
        await asyncio.sleep(0.1)  # warm-up: the loop and the watch started
        worker = threading.Thread(target=hold_the_gil, name="gil-holder")
        if case.endswith("holding the GIL"):
            worker.start()
        cpu0, wall0 = time.process_time(), time.perf_counter()
        await rt.spin(duration_sec=duration_sec)
        cpu1, wall1 = time.process_time(), time.perf_counter()
        stop.set()
        if worker.is_alive():
            worker.join()
        stats = rt.statistics()
    timer = control.timers[0].statistics()
    top = stats["culprits"][0] if stats["culprits"] else None
    return {
        "case": case,
        "core_pct": 100.0 * (cpu1 - cpu0) / (wall1 - wall0),
        "lateness_p99_ms": 1e3 * timer.lateness_p99_sec,
        "late_periods": stats["late_periods"],
        "top_culprit": top.function if top is not None else None,
        "top_culprit_late_periods": top.late_periods if top is not None else 0,
    }


def run(quick: bool = False) -> dict[str, Any]:
    """Every case; ``{"rows": [...], "watch_cost_pct": on - off, "noise": {...}}``."""
    rows, noise = measure_cases(_measure, CASES, 0.3 if quick else 5.0)
    return {
        "period_sec": PERIOD_SEC,
        "rows": rows,
        "watch_cost_pct": rows[1]["core_pct"] - rows[0]["core_pct"],
        "noise": noise,
    }


def table(part: dict[str, Any]) -> Any:
    from ._report import NOISE_COLUMNS, _f, _noise, figure_table

    rows = [
        (
            r["case"], _f(r["core_pct"], 2), _f(r["lateness_p99_ms"], 3), str(r["late_periods"]),
            f"{r['top_culprit']} ({r['top_culprit_late_periods']})" if r["top_culprit"] else "-",
            *_noise(r.get("noise")),
        )
        for r in part.get("rows", [])
    ]
    return figure_table(
        f"Late-period culprits: a {1e3 * part.get('period_sec', PERIOD_SEC):g} ms priority timer",
        ("case", "% of a core", "lateness p99 ms", "late periods", "top culprit (periods)", *NOISE_COLUMNS),
        rows,
        caption=f"watch cost on an idle process (on - off): {_f(part.get('watch_cost_pct'), 2)} % of a core (target <= 1 %)",
    )
