"""Handing work to a loop from any thread, and waking a waiter: the one copy of each.

``call_on`` runs now when the caller is on the loop, else posts; ``post`` always posts (a
delivery that must not run inside the caller's frame); both drop the call quietly once the
loop is closed (shutdown: nobody is left to receive it). ``wake`` resolves a waiter future
unless it is already done (cancelled by a timeout, or woken twice). ``raise_on`` raises an
exception out of a loop, as asyncio lets a task's SystemExit out of ``run_forever``.
"""

from __future__ import annotations

import asyncio
from collections.abc import Callable
from typing import Any

__all__ = ["call_on", "post", "raise_on", "wake"]


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


def raise_on(loop: asyncio.AbstractEventLoop, exc: BaseException) -> None:
    """Raise ``exc`` on ``loop`` from a callback of its own (out of its ``run_forever``, for a
    SystemExit or KeyboardInterrupt: asyncio lets those out), or nothing when the loop has closed."""
    post(loop, _raise, exc)


def _raise(exc: BaseException) -> None:
    raise exc


def wake(waiter: asyncio.Future[Any], exc: BaseException | None = None) -> None:
    """Resolve ``waiter`` (with ``exc`` raised into it, if given) unless it is done already."""
    if waiter.done():
        return
    if exc is None:
        waiter.set_result(None)
    else:
        waiter.set_exception(exc)
