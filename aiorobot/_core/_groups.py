"""Callback groups: which callbacks of a node may run at the same time.

A :class:`MutuallyExclusiveCallbackGroup` holds one lock across the whole callback, awaits
included, so its callbacks never overlap. A :class:`ReentrantCallbackGroup` lets them overlap, a
callback with itself too. Both are async context managers (``async with group:``).
"""

from __future__ import annotations

import asyncio
from collections import deque
from types import TracebackType

__all__ = ["CallbackGroup", "MutuallyExclusiveCallbackGroup", "ReentrantCallbackGroup"]


class CallbackGroup:
    """Base class. ``exclusive`` tells the executor whether to serialise callbacks."""

    exclusive: bool = False
    #: The group's lock, which the executor takes without a coroutine when it is free (None: no
    #: lock, or a subclass's own ``__aenter__``).
    _group_lock: GroupLock | None = None

    async def __aenter__(self) -> None:
        return None

    async def __aexit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        return None


class GroupLock:
    """A FIFO lock for one event loop, taken at once when free (:meth:`try_acquire`, no coroutine
    and no loop turn: every callback of an exclusive group takes it) and handed to the longest
    waiter on release, so a steady stream of callbacks cannot overtake one that waits."""

    __slots__ = ("_held", "_waiters")

    def __init__(self) -> None:
        self._held = False
        self._waiters: deque[asyncio.Future[None]] = deque()

    def locked(self) -> bool:
        return self._held

    def try_acquire(self) -> bool:
        if self._held or self._waiters:
            return False
        self._held = True
        return True

    async def acquire(self) -> None:
        if self.try_acquire():
            return
        waiter: asyncio.Future[None] = asyncio.get_running_loop().create_future()
        self._waiters.append(waiter)
        try:
            await waiter  # release() hands the lock over: it stays held
        except asyncio.CancelledError:
            if waiter.done() and not waiter.cancelled():
                self.release()  # handed over, then cancelled before it could run: pass it on
            else:
                try:
                    self._waiters.remove(waiter)
                except ValueError:
                    pass
            raise

    def release(self) -> None:
        if not self._held:
            raise RuntimeError("GroupLock.release() of a lock that is not held")
        waiters = self._waiters
        while waiters:
            waiter = waiters.popleft()
            if not waiter.done():
                waiter.set_result(None)
                return
        self._held = False


class MutuallyExclusiveCallbackGroup(CallbackGroup):
    """Callbacks of this group never overlap, across awaits included.

    A group belongs to one loop: do not share it between a main-loop node and a priority-loop
    node.
    """

    exclusive = True

    def __init__(self) -> None:
        self._group_lock = GroupLock()

    def locked(self) -> bool:
        return self._group_lock.locked()

    async def __aenter__(self) -> None:
        await self._group_lock.acquire()

    async def __aexit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self._group_lock.release()

    def __repr__(self) -> str:
        return f"<MutuallyExclusiveCallbackGroup {'locked' if self.locked() else 'free'}>"


class ReentrantCallbackGroup(CallbackGroup):
    """Callbacks of this group may overlap, the same callback with itself too."""

    def __repr__(self) -> str:
        return "<ReentrantCallbackGroup>"
