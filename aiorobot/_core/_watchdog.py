"""The runtime's watchdog thread: loop-stall reports and the shutdown deadline.

One daemon thread per runtime. While nothing is wrong it wakes every half
stall threshold and posts one no-op callback to each loop it watches
(``call_soon_threadsafe``); a ping still unanswered after the threshold means a
callback is holding that loop. The watchdog then reads the loop thread's stack
(``sys._current_frames``), finds the node and entity from the ``Node._invoke`` /
``Node._run_hook`` frame on it, reports the stall once per entity with the
stack and counts every stall.

On the first SIGINT/SIGTERM it runs the registered emergency stops (base
controllers' zero commands) in this thread, which no user callback can block,
and arms the shutdown deadline; when the deadline passes, or on a second
signal, it writes what is still blocked to stderr and ends the process with
:data:`EXIT_SHUTDOWN_TIMEOUT`.
"""

from __future__ import annotations

import asyncio
import logging
import os
import queue
import sys
import threading
import time
import traceback
from collections.abc import Callable
from types import FrameType
from typing import Any

__all__ = ["EXIT_SHUTDOWN_TIMEOUT", "Watchdog", "blocked_at"]

_log = logging.getLogger("aiorobot.runtime")

#: exit status when shutdown did not finish within ``shutdown_timeout`` (as coreutils ``timeout``)
EXIT_SHUTDOWN_TIMEOUT = 124
_STACK_FRAMES = 12


class _Watched:
    def __init__(self, name: str, loop: asyncio.AbstractEventLoop, thread_id: int, threshold_sec: float) -> None:
        self.name = name
        self.loop = loop
        self.thread_id = thread_id
        self.threshold_sec = threshold_sec
        self.sent: float | None = None
        self.reported = False

    def answer(self) -> None:
        self.sent = None


def blocked_at(frame: FrameType | None) -> tuple[str, str, str]:
    """``(node, entity, "file:line in function")`` for what runs in ``frame``'s thread."""
    node = entity = ""
    where = ""
    if frame is not None:
        where = f"{os.path.basename(frame.f_code.co_filename)}:{frame.f_lineno} in {frame.f_code.co_name}"
    f = frame
    while f is not None:
        code = f.f_code
        if code.co_name in ("_invoke", "_invoke_now", "_run_hook") and code.co_filename.endswith("_node.py"):
            try:
                local = f.f_locals
                owner = local.get("self")
                node = owner.get_fully_qualified_name() if owner is not None else ""
                if code.co_name in ("_invoke", "_invoke_now"):
                    from ._node import _describe

                    entity = _describe(local.get("entity"))
                else:
                    entity = str(local.get("what", "hook"))
            except Exception:  # a frame read from another thread: best effort
                pass
            break
        f = f.f_back
    return node, entity, where


class Watchdog:
    """Watches loops for stalls and enforces the shutdown deadline (see the module docstring)."""

    def __init__(self) -> None:
        self._watched: list[_Watched] = []
        # Wakes the thread. A SimpleQueue, not a threading.Event: on_signal runs in a signal handler,
        # which can interrupt the main thread inside Event.set() (holding the event's lock) and then
        # wait on that lock for ever; SimpleQueue.put is reentrant, made for signal handlers.
        self._wake: queue.SimpleQueue[None] = queue.SimpleQueue()
        self._closed = False
        self._thread: threading.Thread | None = None
        self._lock = threading.Lock()
        #: stalls counted per ``(loop, node, entity)``
        self.stalls: dict[tuple[str, str, str], int] = {}
        self._reported: set[tuple[str, str, str]] = set()
        self._emergency: list[tuple[str, Callable[[], Any]]] = []
        self._signals = 0
        self._signal_name = ""
        self._emergency_done = False
        self._deadline: float | None = None
        self._timeout_sec = 0.0
        self._finished = False
        self._forced = ""

    # -- configuration ------------------------------------------------------------------

    def watch(self, name: str, loop: asyncio.AbstractEventLoop, thread_id: int, threshold_sec: float) -> None:
        with self._lock:
            self._watched.append(_Watched(name, loop, thread_id, threshold_sec))
        self._ensure_thread()
        self._wake.put(None)

    def unwatch(self, loop: asyncio.AbstractEventLoop) -> None:
        with self._lock:
            self._watched = [w for w in self._watched if w.loop is not loop]

    def add_emergency_stop(self, owner: str, fn: Callable[[], Any]) -> None:
        """Call ``fn()`` from the watchdog thread as soon as a shutdown signal arrives."""
        with self._lock:
            self._emergency.append((owner, fn))

    def remove_emergency_stop(self, fn: Callable[[], Any]) -> None:
        with self._lock:
            self._emergency = [(o, f) for o, f in self._emergency if f != fn]

    # -- signals and deadline -----------------------------------------------------------------

    def on_signal(self, name: str, timeout_sec: float) -> int:
        """Note a shutdown signal (called from a signal handler: no locks, no logging)."""
        self._signals += 1
        if self._signals == 1:
            self._signal_name = name
            self._timeout_sec = timeout_sec
            self._deadline = time.monotonic() + timeout_sec
        else:
            self._forced = name
            self._deadline = time.monotonic()
        self._ensure_thread()
        self._wake.put(None)
        return self._signals

    def finished(self) -> None:
        """The orderly shutdown completed: disarm the deadline and stop the thread."""
        self._finished = True
        self._deadline = None
        self.close()

    def close(self) -> None:
        self._closed = True
        self._wake.put(None)

    def _ensure_thread(self) -> None:
        if self._thread is None and not self._closed:
            self._thread = threading.Thread(target=self._main, name="aiorobot-watchdog", daemon=True)
            self._thread.start()

    # -- the thread --------------------------------------------------------------------------

    def _main(self) -> None:
        while not self._closed:
            now = time.monotonic()
            if self._signals and not self._emergency_done:
                self._emergency_done = True
                self._run_emergency_stops()
            deadline = self._deadline
            if deadline is not None and now >= deadline and not self._finished:
                self._expire()
                return
            with self._lock:
                watched = list(self._watched)
            wait = 0.5
            for w in watched:
                self._check(w, now)
                wait = min(wait, w.threshold_sec / 2)
            if deadline is not None:
                wait = min(wait, max(0.0, deadline - now))
            self._sleep(wait)

    def _sleep(self, timeout_sec: float) -> None:
        """Wait up to ``timeout_sec`` for a wake-up, then take every wake-up queued."""
        try:
            self._wake.get(timeout=timeout_sec)
            while True:
                self._wake.get_nowait()
        except queue.Empty:
            pass

    def _check(self, w: _Watched, now: float) -> None:
        sent = w.sent
        if sent is None:
            w.sent = now
            w.reported = False
            try:
                w.loop.call_soon_threadsafe(w.answer)
            except RuntimeError:  # the loop closed
                w.sent = None
            return
        if w.reported or now - sent <= w.threshold_sec:
            return
        w.reported = True
        frame = sys._current_frames().get(w.thread_id)
        node, entity, _ = blocked_at(frame)
        key = (w.name, node or "?", entity or "?")
        self.stalls[key] = self.stalls.get(key, 0) + 1
        if key in self._reported:
            return
        self._reported.add(key)
        stack = "".join(traceback.format_stack(frame)[-_STACK_FRAMES:]) if frame is not None else ""
        who = f"{entity} in {node}" if node else "a callback"
        _log.warning(
            f"{w.name} loop stalled: {who} has held it for more than {w.threshold_sec * 1000:g} ms "
            f"(reported once, counted in statistics()); it is blocked at:\n{stack.rstrip()}"
        )

    def _run_emergency_stops(self) -> None:
        with self._lock:
            stops = list(self._emergency)
        for owner, fn in stops:
            try:
                fn()
            except Exception as err:
                _log.error(f"emergency stop of {owner} failed: {err!r}")

    def describe_blocked(self) -> list[str]:
        """One line per thread that is not idle: which loop or thread, node, entity and line."""
        frames = sys._current_frames()
        lines = []
        with self._lock:
            watched = list(self._watched)
        seen = set()
        for w in watched:
            seen.add(w.thread_id)
            frame = frames.get(w.thread_id)
            if frame is None:
                continue
            node, entity, where = blocked_at(frame)
            if node or w.sent is not None:
                who = f"{entity} of {node}" if node else "a callback"
                lines.append(f"{w.name} loop: {who} blocked at {where}")
        main = threading.main_thread().ident
        if main is not None and main not in seen and main in frames:
            node, entity, where = blocked_at(frames[main])
            who = f"{entity} of {node}" if node else "shutdown"
            lines.append(f"main thread: {who} blocked at {where}")
        return lines

    def _expire(self) -> None:
        blocked = self.describe_blocked() or ["(no thread identified)"]
        if self._forced:
            why = f"a second signal ({self._forced}) received"
        else:
            why = f"shutdown did not finish within shutdown_timeout = {self._timeout_sec:g} s"
        text = f"aiorobot: {why}; abandoning what is still blocked:\n" + "".join(f"  {b}\n" for b in blocked)
        try:
            sys.stderr.flush()
        except Exception:
            pass
        try:
            os.write(2, text.encode("utf-8", "replace"))
        finally:
            os._exit(EXIT_SHUTDOWN_TIMEOUT)
