"""The priority loop: a second event loop in its own thread for control and fusion nodes.

Its timers wait on a ``timerfd`` (sub-millisecond, no spinning), the thread asks
the kernel for a 1 ns timer slack, and — when permitted and asked for — runs
under ``SCHED_FIFO``. Work on the main loop never delays it, except through the
GIL: a Python thread holding the GIL is made to hand it over after the
interpreter's switch interval, which the runtime shortens while a priority
loop runs.
"""

from __future__ import annotations

import asyncio
import ctypes
import ctypes.util
import logging
import os
import sys
import threading
from typing import Any

from ._waker import LoopWaker, TimerFdWaker, make_waker

__all__ = ["PriorityLoop"]

_log = logging.getLogger("aiorobot.runtime")
_PR_SET_TIMERSLACK = 29


def _new_loop() -> asyncio.AbstractEventLoop:
    try:
        import uvloop
    except ImportError:  # pragma: no cover - uvloop is a dependency off Windows
        return asyncio.new_event_loop()
    return uvloop.new_event_loop()


def _tune_thread(realtime: bool) -> list[str]:
    """Best-effort scheduling tweaks for the calling thread; returns what was applied."""
    applied: list[str] = []
    if sys.platform.startswith("linux"):
        try:
            libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6", use_errno=True)
            if libc.prctl(_PR_SET_TIMERSLACK, ctypes.c_ulong(1), 0, 0, 0) == 0:
                applied.append("timerslack=1ns")
        except OSError:
            pass
        if realtime:
            try:
                os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(10))
                applied.append("SCHED_FIFO")
            except (PermissionError, OSError, AttributeError) as err:
                _log.warning(f"priority loop: SCHED_FIFO not permitted ({err}); running SCHED_OTHER")
    return applied


class PriorityLoop:
    """Owns the priority thread and its event loop."""

    def __init__(self, *, realtime: bool = False) -> None:
        self.realtime = realtime
        self.loop: asyncio.AbstractEventLoop | None = None
        self.waker: LoopWaker | TimerFdWaker | None = None
        self.thread_id: int | None = None
        self.native_id: int | None = None
        self.applied: list[str] = []
        self._thread: threading.Thread | None = None
        self._ready = threading.Event()
        self._error: BaseException | None = None
        #: takes what escapes the loop (a task that raised SystemExit or KeyboardInterrupt, which
        #: asyncio lets out of ``run_forever``); the loop then runs on. None: the thread ends with it.
        self.on_escape: Any = None

    def __repr__(self) -> str:
        state = "running" if self._thread is not None and self._thread.is_alive() else "stopped"
        return f"<PriorityLoop {state} {' '.join(self.applied)}>"

    def start(self) -> None:
        self._thread = threading.Thread(target=self._main, name="aiorobot-priority", daemon=True)
        self._thread.start()
        self._ready.wait()
        if self._error is not None:
            raise RuntimeError("the priority loop failed to start") from self._error

    def _main(self) -> None:
        try:
            self.applied = _tune_thread(self.realtime)
            loop = _new_loop()
            asyncio.set_event_loop(loop)
            self.loop = loop
            self.thread_id = threading.get_ident()
            self.native_id = threading.get_native_id()
            self.waker = make_waker(loop, precise=True)
        except BaseException as err:  # pragma: no cover - reported to start()
            self._error = err
            self._ready.set()
            return
        self._ready.set()
        try:
            while True:
                try:
                    loop.run_forever()
                    break  # stopped
                except BaseException as exc:
                    if self.on_escape is None:
                        raise
                    self.on_escape(exc)
        finally:
            self._finish(loop)

    def _finish(self, loop: asyncio.AbstractEventLoop) -> None:
        pending = [t for t in asyncio.all_tasks(loop) if not t.done()]
        for task in pending:
            task.cancel()
        if pending:
            loop.run_until_complete(asyncio.gather(*pending, return_exceptions=True))
        if self.waker is not None:
            self.waker.close()
        loop.run_until_complete(loop.shutdown_asyncgens())
        asyncio.set_event_loop(None)
        loop.close()

    async def run(self, coro: Any) -> Any:
        """Run ``coro`` on the priority loop and await its result from the calling loop."""
        assert self.loop is not None
        return await asyncio.wrap_future(asyncio.run_coroutine_threadsafe(coro, self.loop))

    def stop(self, timeout: float = 2.0) -> bool:
        """Stop the loop and join its thread for at most ``timeout`` seconds.

        Returns False when a callback still blocks the thread: it is abandoned (a daemon
        thread; its loop stops and closes if the callback ever returns).
        """
        thread = self._thread
        if self.loop is not None and thread is not None and thread.is_alive():
            if not self.loop.is_closed():
                self.loop.call_soon_threadsafe(self.loop.stop)
            thread.join(timeout)
            if thread.is_alive():
                return False
        self._thread = None
        return True
