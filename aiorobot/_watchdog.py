"""Loop-stall monitor and shutdown deadline: a blocked callback never makes a robot unstoppable.

One daemon thread per runtime watches a heartbeat on each of its loops (a loop callback that
stamps ``time.monotonic()`` every quarter threshold: a few dozen calls a second, nothing else
while all is well). A loop whose heartbeat is older than its threshold is *stalled*: the
callback holding it is reported once, with the task that runs it (its name says which node and
timer or topic) and the stack where it blocks (``sys._current_frames``), and counted.

The same thread keeps the shutdown deadline: armed by the first SIGINT/SIGTERM, it ends the
process with a message naming what is still blocked if the orderly shutdown has not finished in
time (or at once on a second signal). It also runs the emergency stops (base controllers' zero
commands) in threads of their own, so no user callback can hold them up.
"""

from __future__ import annotations

import asyncio
import logging
import os
import sys
import threading
import time
import traceback
from collections.abc import Callable
from dataclasses import dataclass, field

__all__ = ["LoopStall", "LoopWatchdog", "StallStatistics"]

_log = logging.getLogger("aiorobot.runtime")

#: Exit status when a shutdown had to abandon blocked threads.
EXIT_SHUTDOWN_TIMEOUT = 1


@dataclass(frozen=True, slots=True)
class LoopStall:
    """One stall as reported: which loop, the task holding it, where it blocks, for how long so far."""

    loop: str
    task: str
    where: str
    seconds: float

    def describe(self) -> str:
        return f"the {self.loop} loop in {self.task!r} at {self.where} ({self.seconds:.1f} s)"


@dataclass(frozen=True, slots=True)
class StallStatistics:
    """Stalls counted per loop name, and the first report of each (latest last)."""

    counts: dict[str, int] = field(default_factory=dict)
    stalls: tuple[LoopStall, ...] = ()


class _Watched:
    def __init__(self, name: str, loop: asyncio.AbstractEventLoop, thread_id: int, threshold: float) -> None:
        self.name = name
        self.loop = loop
        self.thread_id = thread_id
        self.threshold = threshold
        self.last = time.monotonic()
        self.reported = False
        self.count = 0
        self.handle: asyncio.TimerHandle | None = None

    def beat(self) -> None:
        self.last = time.monotonic()
        if not self.loop.is_closed():
            self.handle = self.loop.call_later(self.threshold / 4, self.beat)


class LoopWatchdog:
    """Watches loops for stalls; holds the shutdown deadline and the emergency stops."""

    def __init__(self) -> None:
        self._watched: dict[str, _Watched] = {}
        self._lock = threading.Lock()
        self._wake = threading.Event()
        self._closed = False
        self._deadline: float | None = None
        self._deadline_timeout = 0.0
        self._stalls: list[LoopStall] = []
        self._emergency: list[Callable[[], None]] = []
        self._thread = threading.Thread(target=self._run, name="aiorobot-watchdog", daemon=True)
        self._thread.start()

    def __repr__(self) -> str:
        return f"<LoopWatchdog loops={sorted(self._watched)} stalls={sum(w.count for w in self._watched.values())}>"

    # -- loops --------------------------------------------------------------------------

    def watch(self, name: str, loop: asyncio.AbstractEventLoop, thread_id: int, threshold_sec: float) -> None:
        """Watch ``loop`` (running in thread ``thread_id``); a stall is a heartbeat older than ``threshold_sec``."""
        if not threshold_sec > 0:
            raise ValueError(f"stall threshold for the {name} loop: expected seconds > 0, found {threshold_sec!r}")
        watched = _Watched(name, loop, thread_id, threshold_sec)
        with self._lock:
            self._watched[name] = watched
        loop.call_soon_threadsafe(watched.beat)
        self._wake.set()

    def unwatch(self, name: str) -> None:
        with self._lock:
            watched = self._watched.pop(name, None)
        if watched is not None and watched.handle is not None and not watched.loop.is_closed():
            try:
                watched.loop.call_soon_threadsafe(watched.handle.cancel)
            except RuntimeError:
                pass

    def statistics(self) -> StallStatistics:
        with self._lock:
            return StallStatistics({w.name: w.count for w in self._watched.values()}, tuple(self._stalls))

    def blocked(self) -> list[LoopStall]:
        """The loops stalled right now (whatever their threshold), with where they block."""
        now = time.monotonic()
        with self._lock:
            watched = list(self._watched.values())
        return [self._stall(w, now - w.last) for w in watched if now - w.last > min(w.threshold, 0.25)]

    # -- emergency stops and the shutdown deadline -------------------------------------------

    def add_emergency_stop(self, fn: Callable[[], None]) -> Callable[[], None]:
        """Run ``fn`` first thing on shutdown, in a thread of its own; returns the remover."""
        with self._lock:
            self._emergency.append(fn)

        def remove() -> None:
            with self._lock:
                if fn in self._emergency:
                    self._emergency.remove(fn)

        return remove

    def emergency_stop(self, timeout_sec: float = 0.5) -> None:
        """Run every emergency stop now, each in its own thread; wait up to ``timeout_sec`` in all."""
        with self._lock:
            stops = list(self._emergency)
        threads = [threading.Thread(target=_guarded, args=(fn,), name="aiorobot-emergency-stop", daemon=True) for fn in stops]
        for t in threads:
            t.start()
        end = time.monotonic() + timeout_sec
        for t in threads:
            t.join(max(0.0, end - time.monotonic()))

    def arm_deadline(self, timeout_sec: float) -> None:
        """End the process unless :meth:`close` is called within ``timeout_sec``."""
        with self._lock:
            if self._deadline is None:
                self._deadline = time.monotonic() + timeout_sec
                self._deadline_timeout = timeout_sec
        self._wake.set()

    def force_exit(self, why: str) -> None:
        """Abandon every thread: say what each loop is stuck in and exit now (a second Ctrl-C)."""
        now = time.monotonic()
        with self._lock:
            watched = list(self._watched.values())
        busy = [self._stall(w, now - w.last) for w in watched if self._task_name(w) != "a loop callback" or now - w.last > w.threshold]
        what = "; ".join(s.describe() for s in busy) if busy else "no loop is busy; the shutdown itself was slow"
        sys.stderr.write(f"aiorobot: {why}; exiting without a clean shutdown. Still blocked: {what}\n")
        sys.stderr.flush()
        os._exit(EXIT_SHUTDOWN_TIMEOUT)

    def close(self) -> None:
        self._closed = True
        with self._lock:
            names = list(self._watched)
        for name in names:
            self.unwatch(name)
        self._wake.set()

    # -- the thread ---------------------------------------------------------------------

    def _run(self) -> None:
        while not self._closed:
            with self._lock:
                watched = list(self._watched.values())
                deadline = self._deadline
            period = min([w.threshold / 4 for w in watched] or [0.5])
            if deadline is not None:
                period = min(period, max(0.0, deadline - time.monotonic()))
            self._wake.wait(period)
            self._wake.clear()
            if self._closed:
                return
            now = time.monotonic()
            if deadline is not None and now >= deadline:
                self.force_exit(f"shutdown did not finish within {self._deadline_timeout:g} s")
            for w in watched:
                age = now - w.last
                if age > w.threshold and not w.reported:
                    w.reported = True
                    w.count += 1
                    stall = self._stall(w, age)
                    with self._lock:
                        self._stalls.append(stall)
                        del self._stalls[:-20]
                    _log.warning(
                        f"loop stall: {stall.describe()}: a callback is blocking its loop for longer than "
                        f"{w.threshold:g} s; make it async, or move the work to run_in_thread/offload\n{self._stack(w)}"
                    )
                elif age <= w.threshold and w.reported:
                    w.reported = False

    @staticmethod
    def _task_name(w: _Watched) -> str:
        task = asyncio.tasks._current_tasks.get(w.loop)  # type: ignore[attr-defined]
        return task.get_name() if task is not None else "a loop callback"

    def _stall(self, w: _Watched, age: float) -> LoopStall:
        frame = sys._current_frames().get(w.thread_id)
        where = "?"
        if frame is not None:
            inner = traceback.extract_stack(frame)[-1]
            where = f"{inner.filename}:{inner.lineno} in {inner.name}"
        return LoopStall(w.name, self._task_name(w), where, age)

    @staticmethod
    def _stack(w: _Watched) -> str:
        frame = sys._current_frames().get(w.thread_id)
        if frame is None:
            return ""
        return "".join(traceback.format_stack(frame)[-6:]).rstrip()


def _guarded(fn: Callable[[], None]) -> None:
    try:
        fn()
    except Exception:  # an emergency stop that fails must not stop the others
        _log.exception("an emergency stop raised")
