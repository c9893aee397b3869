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

__all__ = ["wrap_callback"]


def wrap_callback(context: Context, fn: Callable[..., Any] | None) -> Callable[..., Any] | None:
    if fn is None or getattr(fn, "_aiorobot_compat_wrapped", False):
        return fn
    if not callable(fn):
        raise TypeError(f"callback must be callable, got {fn!r}")
    is_async = inspect.iscoroutinefunction(fn)

    @functools.wraps(fn)
    async def callback(*args: Any, **kwargs: Any) -> Any:
        try:
            executor = context.executor
            pool = getattr(executor, "_pool", None)
            if pool is not None and not is_async:
                loop = asyncio.get_running_loop()
                return await loop.run_in_executor(
                    pool, functools.partial(context.call_as_callback, fn, *args, **kwargs)
                )
            result = context.call_as_callback(fn, *args, **kwargs)
            if result is not None and inspect.isawaitable(result):
                result = await result
            return result
        finally:
            context.callback_finished()

    callback._aiorobot_compat_wrapped = True  # type: ignore[attr-defined]
    return callback
