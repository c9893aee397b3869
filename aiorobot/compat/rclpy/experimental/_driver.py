"""What runs the context's event loop while an ``AsyncNode`` is entered, and the hop back to the program.

An rclpy context here is one aiorobot runtime on its own event loop (``Context.loop``), which
runs only while a thread spins. A program written for rclpy's ``AsyncNode`` never spins: it
runs its own asyncio loop (``asyncio.run(main())``) and expects callbacks on it. So while at
least one ``AsyncNode`` is entered, a :class:`Driver` thread spins the context's loop (message
delivery, services, timers, the parameter services, zenoh), and :func:`dispatch` hands each
callback over to the program's loop, as a task of the node's ``TaskGroup`` (where rclpy's
AsyncNode runs it), and hands the result (a service response) back.
"""

from __future__ import annotations

import asyncio
import concurrent.futures
import inspect
import logging
import threading
from collections.abc import Callable
from typing import Any

from ..._context import Context

__all__ = ["Driver", "call_user", "driver_of"]

_log = logging.getLogger("rclpy")


class Driver:
    """Spins ``context``'s loop in a thread while anyone holds it (``acquire`` / ``release``)."""

    def __init__(self, context: Context) -> None:
        self.context = context
        self._lock = threading.Lock()
        self._users = 0
        self._stop = False
        self._thread: threading.Thread | None = None

    def __repr__(self) -> str:
        return f"<AsyncNode driver users={self._users}>"

    def acquire(self) -> None:
        with self._lock:
            self._users += 1
            if self._thread is None:
                self._stop = False
                self._thread = threading.Thread(target=self._main, name="rclpy-asyncnode-driver", daemon=True)
                self._thread.start()

    def release(self) -> threading.Thread | None:
        """One user less; the thread to join when it was the last one."""
        with self._lock:
            self._users -= 1
            if self._users > 0 or self._thread is None:
                return None
            self._stop = True
            thread, self._thread = self._thread, None
        self.context.wake()
        return thread

    def _main(self) -> None:
        context = self.context
        try:
            if context.ok():
                context.spin_until(self, lambda: self._stop, None, raise_on_shutdown=False)
        except Exception:  # noqa: BLE001 - a thread has nowhere else to report
            _log.error("the AsyncNode driver thread stopped", exc_info=True)


def driver_of(context: Context) -> Driver:
    driver = context.__dict__.get("_async_driver")
    if driver is None:
        driver = context.__dict__["_async_driver"] = Driver(context)
    return driver


async def call_user(callback: Callable[..., Any], args: tuple[Any, ...], kwargs: dict[str, Any]) -> Any:
    """``callback(*args)``, awaited when it returns an awaitable (rclpy's ``await_or_execute``)."""
    result = callback(*args, **kwargs)
    if inspect.isawaitable(result):
        result = await result
    return result


def start_on(loop: asyncio.AbstractEventLoop, start: Callable[[], asyncio.Future[Any] | None]) -> concurrent.futures.Future[Any]:
    """Run ``start()`` on ``loop`` (it returns the task to follow, or None to drop); its outcome."""
    outcome: concurrent.futures.Future[Any] = concurrent.futures.Future()

    def begin() -> None:
        try:
            task = start()
        except BaseException as err:  # noqa: BLE001 - handed to the waiting side
            outcome.set_exception(err)
            return
        if task is None:
            outcome.cancel()
            return

        def mirror(t: asyncio.Future[Any]) -> None:
            try:
                if t.cancelled():
                    outcome.cancel()
                elif t.exception() is not None:
                    outcome.set_exception(t.exception())  # type: ignore[arg-type]
                else:
                    outcome.set_result(t.result())
            except concurrent.futures.InvalidStateError:
                pass  # the waiting side gave up (its entity was destroyed) meanwhile

        def abandon(f: concurrent.futures.Future[Any]) -> None:
            if f.cancelled() and not task.done() and not loop.is_closed():
                loop.call_soon_threadsafe(task.cancel)  # the waiting side gave up: so does the callback

        task.add_done_callback(mirror)
        outcome.add_done_callback(abandon)

    if loop.is_closed():
        outcome.cancel()
    else:
        loop.call_soon_threadsafe(begin)
    return outcome
