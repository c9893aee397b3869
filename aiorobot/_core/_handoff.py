"""Handing work to a loop from any thread, and waking a waiter: the one copy of each.

``call_on`` runs now when the caller is on the loop, else posts; ``post`` always posts (a
delivery that must not run inside the caller's frame); both drop the call quietly once the
loop is closed (shutdown: nobody is left to receive it). ``wake`` resolves a waiter future
unless it is already done (cancelled by a timeout, or woken twice).
"""

from __future__ import annotations

import asyncio
from collections.abc import Callable
from typing import Any

__all__ = ["call_on", "post", "wake"]


def call_on(loop: asyncio.AbstractEventLoop, fn: Callable[..., object], *args: Any) -> None:
    """Run ``fn(*args)`` on ``loop``: now if we are on it, else through ``call_soon_threadsafe``."""
    try:
        running = asyncio.get_running_loop()
    except RuntimeError:
        running = None
    if running is loop:
        fn(*args)
    else:
        post(loop, fn, *args)


def post(loop: asyncio.AbstractEventLoop, fn: Callable[..., object], *args: Any) -> None:
    """``loop.call_soon_threadsafe(fn, *args)``, or nothing when the loop has closed."""
    try:
        loop.call_soon_threadsafe(fn, *args)
    except RuntimeError:  # the loop closed during shutdown: nobody is left to receive
        pass


def wake(waiter: asyncio.Future[Any], exc: BaseException | None = None) -> None:
    """Resolve ``waiter`` (with ``exc`` raised into it, if given) unless it is done already."""
    if waiter.done():
        return
    if exc is None:
        waiter.set_result(None)
    else:
        waiter.set_exception(exc)
