"""Part ``cpu``: the CPU cost of a 100 Hz publishing timer, as a share of one core.

The whole process's CPU time (``time.process_time``: every thread) over the
wall time, measured after a short warm-up, for:

- an idle runtime (the floor: nothing but the loop);
- a node publishing a Twist from a 100 Hz timer, no subscriber;
- the same with a subscriber node on the same loop.

The anchor is rclpy's figure for a 100 Hz publisher: 16 % of a core.
"""

from __future__ import annotations

import asyncio
import time
from typing import Any

from ._noise import measure_cases

__all__ = ["RCLPY_REFERENCE_PCT", "run"]

RCLPY_REFERENCE_PCT = 16.0
RATE_HZ = 100.0
CASES = ("idle runtime", "100 Hz publisher", "100 Hz publisher + subscriber")


async def _measure(case: str, duration_sec: float) -> dict[str, Any]:
    from aiorobot import Node, Runtime
    from aiorobot.msgs.geometry_msgs import Twist

    class Talker(Node):
        def __init__(self) -> None:
            super().__init__("talker")
            self.pub = self.create_publisher(Twist, "/cmd_vel", 10)
            self.msg = Twist()
            self.create_timer(1.0 / RATE_HZ, self.tick)

        async def tick(self) -> None:
            self.pub.publish(self.msg)

    class Listener(Node):
        def __init__(self) -> None:
            super().__init__("listener")
            self.count = 0
            self.create_subscription(Twist, "/cmd_vel", self.on_msg, 10)

        async def on_msg(self, msg: Twist) -> None:
            self.count += 1

    async with Runtime(handle_signals=False) as rt:
        if case != "idle runtime":
            rt.add_node(Talker())
        if case.endswith("subscriber"):
            rt.add_node(Listener())
        await asyncio.sleep(0.1)  # warm-up: nodes started, first ticks done
        cpu0, wall0 = time.process_time(), time.perf_counter()
        await rt.spin(duration_sec=duration_sec)
        cpu1, wall1 = time.process_time(), time.perf_counter()
    return {"case": case, "core_pct": 100.0 * (cpu1 - cpu0) / (wall1 - wall0), "wall_sec": wall1 - wall0}


def run(quick: bool = False) -> dict[str, Any]:
    """Measure every case; returns ``{"rows": [...], "reference_pct": 16.0, "noise": {...}}``."""
    rows, noise = measure_cases(_measure, CASES, 0.2 if quick else 5.0)
    return {"rate_hz": RATE_HZ, "rows": rows, "reference": {"rclpy 100 Hz publisher": RCLPY_REFERENCE_PCT}, "noise": noise}
