"""Shared helpers for the perception tests."""

from __future__ import annotations

import asyncio
from collections.abc import Callable


async def wait_until(predicate: Callable[[], bool], timeout_sec: float = 30.0) -> None:
    """Poll a condition on the event loop; returns as soon as it holds (a generous bound, no fixed sleeps)."""
    async with asyncio.timeout(timeout_sec):
        while not predicate():
            await asyncio.sleep(0.005)
