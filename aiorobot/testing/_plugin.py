"""The pytest plugin (entry point ``pytest11``): ``runtime``, ``sim_runtime`` and ``sim_clock`` fixtures."""

from __future__ import annotations

from collections.abc import AsyncIterator

try:
    import pytest_asyncio
except ImportError:  # pragma: no cover - the fixtures need pytest-asyncio
    pytest_asyncio = None  # type: ignore[assignment]

if pytest_asyncio is not None:
    from .._runtime import Runtime
    from ._sim import SimClock

    @pytest_asyncio.fixture
    async def runtime() -> AsyncIterator[Runtime]:
        """A fresh local runtime for one test, shut down after it."""
        async with Runtime(handle_signals=False) as rt:
            yield rt

    @pytest_asyncio.fixture
    async def sim_runtime() -> AsyncIterator[Runtime]:
        """A fresh local runtime with ``use_sim_time=True``."""
        async with Runtime(use_sim_time=True, handle_signals=False) as rt:
            yield rt

    @pytest_asyncio.fixture
    async def sim_clock(sim_runtime: Runtime) -> SimClock:
        """A :class:`SimClock` driving ``sim_runtime``, started at t = 1 s."""
        clock = SimClock(sim_runtime, start_sec=1.0)
        await clock.start()
        return clock
