"""``rclpy.executors`` on aiorobot: single- and multi-threaded executors driving one runtime."""

from __future__ import annotations

import concurrent.futures
import os
from collections.abc import Callable
from typing import Any

from ..._core._future import Future
from .._context import Context, ExternalShutdownException, default_context
from .._missing import module_getattr

__all__ = [
    "ConditionReachedException",
    "Executor",
    "ExternalShutdownException",
    "Handler",
    "MultiThreadedExecutor",
    "ShutdownException",
    "SingleThreadedExecutor",
    "TimeoutException",
]


class ShutdownException(Exception):
    """rclpy's: the executor was shut down."""


class TimeoutException(Exception):
    """rclpy's: a wait timed out."""


class ConditionReachedException(Exception):
    """rclpy's: ``wait_for_ready_callbacks``' condition held."""


class Handler(Future[Any]):
    """What ``wait_for_ready_callbacks`` hands out (rclpy's ``Task``): call it once to run the callback."""

    def __init__(self, runner: Callable[[], Any]) -> None:
        super().__init__()
        self._runner: Callable[[], Any] | None = runner

    def __call__(self) -> None:
        runner, self._runner = self._runner, None
        if runner is None:
            return  # already run, as calling an rclpy Task twice does nothing
        try:
            result = runner()
        except BaseException as err:  # delivered to the callback's task, which logs it
            self.set_exception(err)
        else:
            self.set_result(result)


class Executor:
    """rclpy's ``Executor``: ``add_node``, ``spin``, ``spin_once``, ``spin_until_future_complete``.

    Differences from rclpy: every node of the context is served whichever executor
    spins (aiorobot's runtime runs the whole graph). ``spin_once`` starts one callback, as
    rclpy's; what becomes ready meanwhile waits for the next spin.
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
        with self._context.spinning():
            if type(self).spin_once is not Executor.spin_once:
                # a custom executor: rclpy's spin calls its spin_once, which takes work with
                # wait_for_ready_callbacks
                while self._context.ok() and not self._is_shutdown:
                    self.spin_once()
                return
            while self._context.ok() and not self._is_shutdown:
                self._context.spin_until(self, lambda: self._is_shutdown, None, raise_on_shutdown=True)

    def wait_for_ready_callbacks(
        self, timeout_sec: float | None = None, nodes: list[Any] | None = None,
        condition: Callable[[], bool] = lambda: False,
    ) -> tuple[Handler, Any, Any]:
        """The next ready plain callback as ``(handler, entity, node)``; call ``handler()`` to run it.

        As rclpy's: runs the graph until a callback of ``nodes`` (default: this executor's)
        is ready, ``TimeoutException`` after ``timeout_sec``, ``ShutdownException`` when the
        context or executor shuts down, ``ConditionReachedException`` when ``condition()``
        holds. The callback runs in whichever thread calls the handler; aiorobot's own work
        (message delivery, service plumbing, ``async def`` callbacks) keeps running while
        this waits.
        """
        ctx = self._context
        ctx.raise_if_interrupted()
        if self._is_shutdown or not ctx.ok():
            raise ShutdownException()
        wanted = self._nodes if nodes is None else list(nodes)

        def mine() -> list[Any]:
            return [e for e in ctx.ready_runners() if e[2] is not None and e[2][0] in wanted]

        ctx.spin_until(
            self, lambda: bool(mine()) or condition() or self._is_shutdown, timeout_sec,
            raise_on_shutdown=False, admissions=0,
        )
        ready = mine()
        if ready:
            waiter, runner, (node, slot) = ready[0]
            handler = Handler(runner)
            waiter.set_result(handler)
            return handler, (slot[0] if slot else None), node
        if self._is_shutdown or not ctx.ok():
            raise ShutdownException()
        if condition():
            raise ConditionReachedException()
        raise TimeoutException()

    def spin_once(self, timeout_sec: float | None = None) -> None:
        ctx = self._context
        start = ctx.callbacks_done
        if timeout_sec == 0:
            ctx.spin_until(self, lambda: True, 0, raise_on_shutdown=True, admissions=1)
            return
        ctx.spin_until(self, lambda: ctx.callbacks_done != start, timeout_sec, raise_on_shutdown=True, admissions=1)

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


_MISSING = frozenset({"await_or_execute", "TaskData"})
__getattr__ = module_getattr(__name__, "rclpy.executors", _MISSING)
