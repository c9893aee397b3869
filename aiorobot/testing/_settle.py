"""Letting a runtime catch up: run both loops until every queue is handled."""

from __future__ import annotations

import asyncio

from .._core._runtime import Runtime

__all__ = ["settle"]


async def settle(runtime: Runtime, *, rounds: int = 3, max_rounds: int = 1000) -> None:
    """Run the main and priority loops until every subscription queue has been handled.

    Waits for ``rounds`` consecutive quiet passes (a pass yields to the main loop and
    makes a round trip through the priority loop). Callbacks waiting on I/O or on
    time may still be pending afterwards: wait for their effects with events.
    """
    quiet = 0
    for _ in range(max_rounds):
        await asyncio.sleep(0)
        prio = runtime.priority_loop
        if prio is not None and prio.loop is not None:
            await prio.run(asyncio.sleep(0))
        if all(node._idle() for node in runtime.nodes):
            quiet += 1
            if quiet >= rounds:
                return
        else:
            quiet = 0
