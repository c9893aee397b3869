"""Blocking until a condition holds, from wherever an rclpy program calls a blocking tf2_ros method.

tf2_ros's ``lookup_transform(..., timeout)`` sleeps in the calling thread while the
listener, spun by another thread, fills the buffer. On aiorobot the listener's
subscriptions run on the context's event loop, so the wait has to keep that loop
running, wherever the call comes from:

- the loop runs in another thread (a MultiThreadedExecutor's pool, a user thread while
  the main thread spins): wait on a ``threading.Event`` that every insert sets;
- nothing runs the loop (the main thread between spins): run it here until the
  condition holds, as a blocking ``Client.call`` does;
- the loop is running in this very thread (a plain callback of a SingleThreadedExecutor):
  run further iterations of that loop from inside the callback until the condition holds.
  The callback's own task is set aside meanwhile, so every other task and subscription
  proceeds; callbacks of the waiting callback's mutually exclusive group wait for it,
  as under rclpy.

Upstream (geometry2 issue 327) a SingleThreadedExecutor's callback that waits starves
the listener and always times out; here the listener keeps receiving.
"""

from __future__ import annotations

import asyncio
import asyncio.tasks
import threading
import time
from collections.abc import Callable

from .._context import Context, default_context

__all__ = ["block_until"]


def _noop() -> None:
    pass


def _run_nested(loop: asyncio.AbstractEventLoop, ctx: Context, ready: Callable[[], bool], timeout_sec: float) -> None:
    """Iterate ``loop`` (running in this thread, inside a task step) until ``ready()`` or the timeout."""
    run_once = getattr(loop, "_run_once", None)
    if run_once is None:  # pragma: no cover - an event loop without asyncio's base implementation
        raise RuntimeError(
            f"a blocking tf2_ros wait inside a callback needs asyncio's own event loop, found {type(loop).__name__}; "
            "use the _async form (await buffer.lookup_transform_async(...)) instead"
        )
    deadline = loop.time() + timeout_sec
    wake_at_deadline = loop.call_at(deadline, _noop)
    task = asyncio.current_task(loop)
    if task is not None:
        asyncio.tasks._leave_task(loop, task)  # type: ignore[attr-defined]
    stopping = False
    try:
        while not ready() and ctx.ok() and loop.time() < deadline:
            # a stop requested meanwhile (a spin_once whose condition held) is kept for the outer
            # loop: left set, it would make every iteration here poll instead of waiting
            if getattr(loop, "_stopping", False):
                stopping = True
                loop._stopping = False  # type: ignore[attr-defined]
            run_once()
    finally:
        wake_at_deadline.cancel()
        if stopping or getattr(loop, "_stopping", False):
            loop._stopping = True  # type: ignore[attr-defined]
        if task is not None:
            asyncio.tasks._enter_task(loop, task)  # type: ignore[attr-defined]


def block_until(
    ready: Callable[[], bool],
    timeout_sec: float,
    subscribe: Callable[[Callable[[], None]], Callable[[], None]],
    context: Context | None = None,
) -> bool:
    """Block the calling thread up to ``timeout_sec`` until ``ready()``; whether it holds.

    ``subscribe(callback)`` must arrange for ``callback()`` to be called after every change
    that may make ``ready()`` true (from any thread) and return a function that undoes it.
    """
    if ready():
        return True
    if timeout_sec <= 0:
        return False
    ctx = context or default_context()
    loop = ctx.loop
    if ctx.ok() and loop is not None and not loop.is_closed():
        if loop.is_running() and ctx._spin_thread == threading.get_ident():
            _run_nested(loop, ctx, ready, timeout_sec)
            return ready()
        if not loop.is_running() and not ctx._spin_lock.locked():
            unsubscribe = subscribe(ctx.wake)
            try:
                ctx.spin_until(ctx.executor, ready, timeout_sec, raise_on_shutdown=False)
            finally:
                unsubscribe()
            return ready()
    # another thread runs the loop (or nothing ever will): inserts set the event
    event = threading.Event()
    unsubscribe = subscribe(event.set)
    try:
        deadline = time.monotonic() + timeout_sec
        while not ready():
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                return False
            event.wait(remaining)
            event.clear()
        return True
    finally:
        unsubscribe()

