"""``rclpy.executors`` on aiorobot: single- and multi-threaded executors driving one runtime."""

from __future__ import annotations

import concurrent.futures
import os
from collections.abc import Callable
from typing import Any

from ..._future import Future
from .._context import Context, ExternalShutdownException, default_context
from .._missing import module_getattr

__all__ = [
    "Executor",
    "ExternalShutdownException",
    "MultiThreadedExecutor",
    "ShutdownException",
    "SingleThreadedExecutor",
    "TimeoutException",
]


class ShutdownException(Exception):
    """rclpy's: the executor was shut down."""


class TimeoutException(Exception):
    """rclpy's: a wait timed out."""


class Executor:
    """rclpy's ``Executor``: ``add_node``, ``spin``, ``spin_once``, ``spin_until_future_complete``.

    Differences from rclpy: every node of the context is served whichever executor
    spins (aiorobot's runtime runs the whole graph); ``spin_once`` handles the callbacks
    ready when it runs, which may be more than one.
    """

    _pool: concurrent.futures.ThreadPoolExecutor | None = None

    def __init__(self, *, context: Context | None = None) -> None:
        self._context = context or default_context()
        self._nodes: list[Any] = []
        self._is_shutdown = False

    @property
    def context(self) -> Context:
        return self._context

    def add_node(self, node: Any) -> bool:
        if node in self._nodes:
            return False
        self._nodes.append(node)
        node._executor_ref = self
        return True

    def remove_node(self, node: Any) -> None:
        if node in self._nodes:
            self._nodes.remove(node)

    def get_nodes(self) -> list[Any]:
        return list(self._nodes)

    def wake(self) -> None:
        self._context.wake()

    def create_task(self, callback: Callable[..., Any], *args: Any, **kwargs: Any) -> Future[Any]:
        """Run ``callback(*args)`` (a coroutine function or a plain one) on the executor; its Future."""
        from .._dispatch import wrap_callback

        ctx = self._context
        ctx.require_ok("create_task")
        wrapped = wrap_callback(ctx, callback)
        assert wrapped is not None and ctx.loop is not None
        fut: Future[Any] = Future()

        def start() -> None:
            task = ctx.loop.create_task(wrapped(*args, **kwargs))  # type: ignore[union-attr]

            def mirror(t: Any) -> None:
                if t.cancelled():
                    fut.cancel()
                elif t.exception() is not None:
                    fut.set_exception(t.exception())
                else:
                    fut.set_result(t.result())

            task.add_done_callback(mirror)

        ctx.loop.call_soon_threadsafe(start)
        return fut

    def spin(self) -> None:
        while self._context.ok() and not self._is_shutdown:
            self._context.spin_until(self, lambda: self._is_shutdown, None, raise_on_shutdown=True)

    def spin_once(self, timeout_sec: float | None = None) -> None:
        ctx = self._context
        start = ctx.callbacks_done
        if timeout_sec == 0:
            ctx.spin_until(self, lambda: True, 0, raise_on_shutdown=True)
            return
        ctx.spin_until(self, lambda: ctx.callbacks_done != start, timeout_sec, raise_on_shutdown=True)

    def spin_until_future_complete(self, future: Any, timeout_sec: float | None = None) -> None:
        ctx = self._context
        if hasattr(future, "add_done_callback"):
            future.add_done_callback(lambda _f: ctx.wake())
        if future.done():
            return
        ctx.spin_until(self, future.done, timeout_sec, raise_on_shutdown=False)

    def spin_once_until_future_complete(self, future: Any, timeout_sec: float | None = None) -> None:
        self.spin_until_future_complete(future, timeout_sec)

    def shutdown(self, timeout_sec: float | None = None) -> bool:
        self._is_shutdown = True
        self._context.wake()
        pool, self._pool = self._pool, None
        if pool is not None:
            pool.shutdown(wait=False, cancel_futures=True)
        return True

    def __enter__(self) -> Executor:
        return self

    def __exit__(self, *exc: object) -> None:
        self.shutdown()


class SingleThreadedExecutor(Executor):
    """Callbacks run one at a time in the thread that spins."""


class MultiThreadedExecutor(Executor):
    """Plain-function callbacks run in a pool of ``num_threads`` threads.

    Callbacks of one ``MutuallyExclusiveCallbackGroup`` (a node's default group) never
    overlap; callbacks of a ``ReentrantCallbackGroup`` run in parallel threads, as rclpy.
    ``async def`` callbacks run on the event loop in the spinning thread.
    """

    def __init__(self, num_threads: int | None = None, *, context: Context | None = None) -> None:
        super().__init__(context=context)
        if num_threads is None:
            num_threads = os.cpu_count() or 2
        if num_threads <= 0:
            raise ValueError(f"MultiThreadedExecutor: expected num_threads > 0, found {num_threads!r}")
        self._num_threads = num_threads
        self._pool = concurrent.futures.ThreadPoolExecutor(num_threads, thread_name_prefix="rclpy-executor")


_MISSING = frozenset({"await_or_execute", "ConditionReachedException", "TaskData"})
__getattr__ = module_getattr(__name__, "rclpy.executors", _MISSING)
