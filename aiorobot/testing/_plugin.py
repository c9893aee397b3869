"""The pytest plugin (entry point ``pytest11``): ``runtime``, ``sim_runtime``, ``sim_clock`` and ``bag_replay`` fixtures."""

from __future__ import annotations

import inspect
from collections.abc import AsyncIterator
from typing import Any

import pytest

#: the fixtures this plugin provides; an ``async def`` test using one runs under pytest-asyncio
FIXTURES = frozenset({"runtime", "sim_runtime", "sim_clock", "bag_replay"})

try:
    import pytest_asyncio
except ImportError:  # pragma: no cover - the fixtures need pytest-asyncio
    pytest_asyncio = None  # type: ignore[assignment]

if pytest_asyncio is not None:
    from .._core._runtime import Runtime
    from ._bag import BagReplay
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

    @pytest.fixture
    def bag_replay() -> BagReplay:
        """A :class:`BagReplay`: ``await bag_replay.assert_matches(path, NodeClass)`` is a regression test."""
        return BagReplay()


@pytest.hookimpl(tryfirst=True)
def pytest_pycollect_makeitem(collector: Any, name: str, obj: Any) -> None:
    """Mark ``async def`` tests that use our fixtures with ``pytest.mark.asyncio``.

    So they run in a project that leaves pytest-asyncio in its default strict mode
    (no ``asyncio_mode = "auto"`` needed).
    """
    if pytest_asyncio is None or not inspect.iscoroutinefunction(obj):
        return
    try:
        uses = FIXTURES & set(inspect.signature(obj).parameters)
    except (TypeError, ValueError):
        return
    marks = getattr(obj, "pytestmark", [])
    if uses and not any(getattr(m, "name", "") == "asyncio" for m in marks):
        obj.pytestmark = [*marks, pytest.mark.asyncio]
