"""Where an rclpy callback runs: in the spinning thread, or a MultiThreadedExecutor's thread pool.

Every callback a program hands to the compat layer is wrapped once. A plain function
runs in the thread that spins (SingleThreadedExecutor) or in the pool of the
:class:`MultiThreadedExecutor` that spins; aiorobot's callback groups still decide
what may overlap (a mutually exclusive group's lock is held across the pool call).
An ``async def`` callback runs on the event loop, as aiorobot runs it.
"""

from __future__ import annotations

import asyncio
import functools
import inspect
from collections.abc import Callable
from typing import Any

from ._context import Context

__all__ = ["gate_callback", "wrap_callback"]


def wrap_callback(context: Context, fn: Callable[..., Any] | None, owner: Any = None) -> Callable[..., Any] | None:
    """``fn`` as the executor runs it; ``owner`` ``(node, entity slot)`` is what a custom executor is told."""
    if fn is None or getattr(fn, "_aiorobot_compat_wrapped", False):
        return fn
    if not callable(fn):
        raise TypeError(f"callback must be callable, got {fn!r}")
    is_async = inspect.iscoroutinefunction(fn)

    @functools.wraps(fn)
    async def callback(*args: Any, **kwargs: Any) -> Any:
        runner = None if is_async else functools.partial(context.call_as_callback, fn, *args, **kwargs)
        handler = await context.admit(runner, owner)
        try:
            if handler is not None:  # a custom executor took it: it runs where the executor calls it
                return await handler
            executor = context.executor
            pool = getattr(executor, "_pool", None)
            try:
                if pool is not None and not is_async:
                    loop = asyncio.get_running_loop()
                    return await loop.run_in_executor(
                        pool, functools.partial(context.call_as_callback, fn, *args, **kwargs)
                    )
                result = context.call_as_callback(fn, *args, **kwargs)
                if result is not None and inspect.isawaitable(result):
                    result = await result
                return result
            except SystemExit as exc:  # the spin raises it; this entity goes on
                context.exit_from_callback(exc)
                return None
        finally:
            context.callback_finished()

    callback._aiorobot_compat_wrapped = True  # type: ignore[attr-defined]
    return callback


def gate_callback(context: Context, group: Any, callback: Callable[..., Any], entity: Callable[[], Any], *, coalesce: bool) -> Callable[..., Any]:
    """``callback`` run only when the program's own ``group`` says ``beginning_execution(entity)``.

    A refused call waits for the next callback of the program to finish and asks again, as
    rclpy's executor asks on each pass. ``coalesce`` (timers): while one call waits, further
    ones are dropped, as an rcl timer stays ready once and skips the periods it missed.
    """
    waiting = False

    @functools.wraps(callback)
    async def gated(*args: Any, **kwargs: Any) -> Any:
        nonlocal waiting
        if coalesce and waiting:
            return None
        waiting = True
        try:
            while not group.beginning_execution(entity()):
                await context.next_callback_finished()
        finally:
            waiting = False
        try:
            return await callback(*args, **kwargs)
        finally:
            group.ending_execution(entity())

    gated._aiorobot_compat_wrapped = True  # type: ignore[attr-defined]
    return gated
