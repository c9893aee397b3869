"""Executor models ``aiorobot`` and ``aiorobot-rt``: the seed experiment as a user writes it.

The control node runs on the priority loop; the perception node stays on the
main loop and sends its 150 ms of work to the runtime's process pool with
``Node.offload``. ``aiorobot`` uses ``Runtime()`` as it comes; ``aiorobot-rt``
asks for ``Runtime(priority_realtime=True)`` (the priority thread under
SCHED_FIFO where the OS permits it). Nothing here reaches into the runtime's
internals beyond reading which scheduling tweaks were applied.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import TYPE_CHECKING

from ._seedconfig import SeedConfig
from ._workload import work_function

if TYPE_CHECKING:
    from aiorobot import Node

__all__ = ["run_aiorobot", "run_aiorobot_rt"]


def _nodes(kind: str, cfg: SeedConfig, done: Callable[[], None]) -> tuple[Node, Node]:
    from aiorobot import Node

    class Control(Node):
        """A 50 Hz control loop: records when each tick starts."""

        def __init__(self) -> None:
            super().__init__("control")
            self.stamps: list[float] = []
            self.create_timer(cfg.control_period_sec, self.tick)

        async def tick(self) -> None:
            self.stamps.append(time.perf_counter())
            if len(self.stamps) == cfg.stamps_needed:
                done()

    class Perception(Node):
        """150 ms of work every 100 ms, in the process pool."""

        def __init__(self) -> None:
            super().__init__("perception")
            self.work = work_function(kind)
            self.create_timer(cfg.perception_period_sec, self.perceive)

        async def perceive(self) -> None:
            await self.offload(self.work, cfg.work_sec)

    return Control(), Perception()


async def _main(kind: str, cfg: SeedConfig, realtime: bool, applied: list[str]) -> list[float]:
    from aiorobot import Runtime

    async with Runtime(handle_signals=False, priority_realtime=realtime) as rt:
        control, perception = _nodes(kind, cfg, rt.shutdown)
        rt.add_node(control, executor="priority")
        rt.add_node(perception)
        if rt.priority_loop is not None:
            applied.extend(rt.priority_loop.applied)
        await rt.spin()
    return list(getattr(control, "stamps"))


def run_aiorobot(kind: str, cfg: SeedConfig, *, realtime: bool = False, applied: list[str] | None = None) -> list[float]:
    """Run the model; returns the control callback's start stamps in seconds.

    ``applied`` (if given) receives the priority thread's scheduling tweaks
    (``"timerslack=1ns"``, ``"SCHED_FIFO"``).
    """
    import aiorobot

    return aiorobot.run(_main(kind, cfg, realtime, applied if applied is not None else []))


def run_aiorobot_rt(kind: str, cfg: SeedConfig, *, applied: list[str] | None = None) -> list[float]:
    """The ``aiorobot-rt`` model: the same nodes on ``Runtime(priority_realtime=True)``."""
    return run_aiorobot(kind, cfg, realtime=True, applied=applied)
