"""Callback groups: which callbacks of a node may run at the same time.

A :class:`MutuallyExclusiveCallbackGroup` holds one ``asyncio.Lock`` across the
whole callback, awaits included, so its callbacks never overlap. A
:class:`ReentrantCallbackGroup` lets them overlap, a callback with itself too.
Both are async context managers (``async with group:``).
"""

from __future__ import annotations

import asyncio
from types import TracebackType

__all__ = ["CallbackGroup", "MutuallyExclusiveCallbackGroup", "ReentrantCallbackGroup"]


class CallbackGroup:
    """Base class. ``exclusive`` tells the executor whether to serialise callbacks."""

    exclusive: bool = False

    async def __aenter__(self) -> None:
        return None

    async def __aexit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        return None


class MutuallyExclusiveCallbackGroup(CallbackGroup):
    """Callbacks of this group never overlap, across awaits included.

    The lock binds to the event loop of its first contended use, so a group
    belongs to one loop: do not share it between a main-loop node and a
    priority-loop node.
    """

    exclusive = True

    def __init__(self) -> None:
        self._lock = asyncio.Lock()

    def locked(self) -> bool:
        return self._lock.locked()

    async def __aenter__(self) -> None:
        await self._lock.acquire()

    async def __aexit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self._lock.release()

    def __repr__(self) -> str:
        return f"<MutuallyExclusiveCallbackGroup {'locked' if self.locked() else 'free'}>"


class ReentrantCallbackGroup(CallbackGroup):
    """Callbacks of this group may overlap, the same callback with itself too."""

    def __repr__(self) -> str:
        return "<ReentrantCallbackGroup>"
