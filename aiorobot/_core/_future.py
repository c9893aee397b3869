"""rclpy-style futures: what ``call_async``, ``send_goal_async`` and friends return.

A :class:`Future` is rclpy's ``rclpy.task.Future`` on asyncio: ``done()``,
``result()``, ``exception()``, ``cancel()``, ``cancelled()``,
``add_done_callback(cb)`` (``cb(future)``), ``set_result``/``set_exception``,
and ``await future`` from any event loop. It is thread-safe, so a future
completed on one loop (say, the node's) can be awaited on another.
"""

from __future__ import annotations

import asyncio
import concurrent.futures
import logging
import threading
from collections.abc import Callable, Coroutine, Generator
from typing import Any, Generic, TypeVar

from ._handoff import call_on, wake

__all__ = ["Future", "future_of"]

T = TypeVar("T")

_log = logging.getLogger("aiorobot")


class Future(Generic[T]):
    """The outcome of an operation that finishes later (rclpy's ``Future``).

    ``result()`` returns the result (``None`` while not done, or after a
    cancel) and raises the exception the operation raised; ``exception()``
    returns it instead. Done callbacks run on the event loop that completes the
    future (at once when there is none), in the order they were added; one added
    to a finished future is scheduled right away.

    rclpy difference: ``cancel()`` makes the future done (``done()`` is ``True``,
    as in asyncio; rclpy leaves it ``False``), cancels the operation behind it,
    and ``await future`` then raises ``asyncio.CancelledError`` instead of
    waiting forever.
    """

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._done = False
        self._cancelled = False
        self._result: T | None = None
        self._exception: BaseException | None = None
        self._callbacks: list[Callable[[Future[T]], Any]] = []
        self._waiters: list[tuple[asyncio.AbstractEventLoop, asyncio.Future[None]]] = []
        self._on_cancel: Callable[[], Any] | None = None

    def __repr__(self) -> str:
        if not self._done:
            state = "pending"
        elif self._cancelled:
            state = "cancelled"
        elif self._exception is not None:
            state = f"exception={self._exception!r}"
        else:
            state = f"result={self._result!r}"
        return f"<Future {state}>"

    # -- reading ------------------------------------------------------------------

    def done(self) -> bool:
        """True once a result or exception is set, or the future was cancelled."""
        return self._done

    def cancelled(self) -> bool:
        return self._cancelled

    def result(self) -> T | None:
        """The result; ``None`` while not done or after a cancel. Raises the operation's exception."""
        if self._exception is not None:
            raise self._exception
        return self._result

    def exception(self) -> BaseException | None:
        """The exception the operation raised, or ``None``."""
        return self._exception

    def __await__(self) -> Generator[Any, None, T | None]:
        try:
            loop = asyncio.get_running_loop()
        except RuntimeError:  # driven by hand (coroutine.send), as rclpy's executor does
            while not self._done:
                yield None
            loop = None
        if not self._done and loop is not None:
            waiter: asyncio.Future[None] = loop.create_future()
            with self._lock:
                pending = not self._done
                if pending:
                    self._waiters.append((loop, waiter))
            if pending:
                try:
                    yield from waiter.__await__()
                finally:
                    with self._lock:
                        if (loop, waiter) in self._waiters:
                            self._waiters.remove((loop, waiter))
        if self._cancelled:
            raise asyncio.CancelledError(f"{self!r} was cancelled")
        return self.result()

    # -- completing ---------------------------------------------------------------

    def set_result(self, result: T) -> None:
        self._finish(result=result)

    def set_exception(self, exception: BaseException) -> None:
        self._finish(exception=exception)

    def cancel(self) -> bool:
        """Cancel the operation if it is not done yet; True when this call cancelled it."""
        if not self._finish(cancelled=True):
            return False
        on_cancel, self._on_cancel = self._on_cancel, None
        if on_cancel is not None:
            on_cancel()
        return True

    def _finish(self, *, result: Any = None, exception: BaseException | None = None, cancelled: bool = False) -> bool:
        with self._lock:
            if self._done:
                return False
            self._done = True
            self._cancelled = cancelled
            self._result = result
            self._exception = exception
            callbacks, self._callbacks = self._callbacks, []
            waiters, self._waiters = self._waiters, []
        for loop, waiter in waiters:
            call_on(loop, wake, waiter)
        for callback in callbacks:
            self._run_callback(callback)
        return True

    def add_done_callback(self, callback: Callable[[Future[T]], Any]) -> None:
        """Call ``callback(future)`` when done (scheduled now if already done)."""
        if not callable(callback):
            raise TypeError(f"add_done_callback expects a callable, got {callback!r}")
        with self._lock:
            if not self._done:
                self._callbacks.append(callback)
                return
        self._run_callback(callback)

    def _run_callback(self, callback: Callable[[Future[T]], Any]) -> None:
        try:
            loop = asyncio.get_running_loop()
        except RuntimeError:
            try:
                callback(self)
            except Exception:
                _log.error("done callback %r of %r raised", callback, self, exc_info=True)
            return
        loop.call_soon(callback, self)


def future_of(coro: Coroutine[Any, Any, T], loop: asyncio.AbstractEventLoop | None = None) -> Future[T]:
    """Run ``coro`` as a task on ``loop`` (default: the running loop) and return its :class:`Future`.

    From another thread, ``loop`` must be given; the task is started there.
    Cancelling the future cancels the task.
    """
    fut: Future[T] = Future()
    try:
        running: asyncio.AbstractEventLoop | None = asyncio.get_running_loop()
    except RuntimeError:
        running = None
    target = loop or running
    if target is None:
        coro.close()
        raise RuntimeError("no event loop: call this from a callback or coroutine, or start the runtime first")

    def mirror(done: asyncio.Future[T] | concurrent.futures.Future[T]) -> None:
        if done.cancelled():
            fut._finish(cancelled=True)
        elif done.exception() is not None:
            fut.set_exception(done.exception())  # type: ignore[arg-type]
        else:
            fut.set_result(done.result())

    if target is running:
        task: asyncio.Task[T] = target.create_task(coro)
        task.add_done_callback(mirror)
        fut._on_cancel = task.cancel
    else:
        cfut = asyncio.run_coroutine_threadsafe(coro, target)
        cfut.add_done_callback(mirror)
        fut._on_cancel = cfut.cancel
    return fut
