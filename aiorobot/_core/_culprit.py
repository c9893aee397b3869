"""The culprit of a late priority period: what held the priority loop when its timer was due.

A priority-loop timer fires late for one of two reasons: a callback on that loop was
still running at the deadline, or another thread held the GIL. The priority loop's
50 us switch interval makes a thread running bytecode hand the GIL over quickly, so the
usual holders are long C calls made from Python (``sum(range(N))``, a numpy operation
that keeps the GIL), on the main loop or in a thread of one's own.

:class:`LateWatch` finds it with one sampling thread that works only around a deadline:

1. The priority timers tell it their next deadline (:meth:`LateWatch.arm`, a dict store).
2. Shortly before the deadline (:data:`LEAD_SEC`) it reads every Python thread's CPU
   time (``pthread_getcpuclockid``; a few microseconds). When that read itself comes late
   (a C call held the GIL across it), the previous read serves as the starting point.
3. At ``deadline + late_threshold`` it looks whether the timer has fired
   (:meth:`LateWatch.fired`, a dict store on the priority thread). It has: nothing more.
4. It has not, so the deadline is at risk: once the sampler gets the GIL (a C call
   holding it lets go first), the thread whose CPU time grew most since step 2 is the
   one that held the loop: the GIL holder, or the priority thread itself when one of
   its callbacks overran. That thread's stack (``sys._current_frames``) is read then:
   the holder has only just let go and still sits in the function that made the call.
   The culprit is named by the innermost frame of code that is neither the standard
   library, an installed package nor aiorobot (the callback, not ``numpy/...``), with
   the node and entity when it ran as a node callback. When an event loop's thread ran
   most but its callback has already returned, the node callback that ran longest on
   that loop since step 2 is named (the runtime keeps each node's last one); with none,
   ``(main loop between callbacks)`` (the loop's own I/O and timers).
5. When the timer fires, its lateness is added to that culprit.

Watching a deadline costs two wake-ups of the sampler; deadlines closer together than
:data:`MIN_GAP_SEC` are watched one in every few (a 1 kHz timer: one in five), so the
cost stays below 1 % of a core (``aiorobot bench latency --only culprit`` measures it).
Late periods the sampler did not watch are counted as ``(not sampled)``; a late period
during which no Python thread ran (another process, the OS) as ``(no Python thread)``.
Timers on sim time are not watched.
"""

from __future__ import annotations

import functools
import inspect
import os
import sys
import sysconfig
import threading
import time
from dataclasses import dataclass
from collections.abc import Callable
from types import FrameType
from typing import Any

from ._watchdog import blocked_at

__all__ = ["LEAD_SEC", "MIN_GAP_SEC", "Culprit", "LateWatch"]

#: how long before a deadline the sampler reads the threads' CPU times
LEAD_SEC = 0.0003
#: the sampler watches at most one deadline in this span
MIN_GAP_SEC = 0.004
#: how long the sampler waits, after sampling, for a late timer to fire before it gives up on it
_FIRE_WAIT_SEC = 1.0
NOT_SAMPLED = "(not sampled)"
NO_PYTHON = "(no Python thread)"


@dataclass(frozen=True, slots=True)
class Culprit:
    """What made priority periods late, and by how much in total."""

    function: str
    where: str
    node: str
    entity: str
    thread: str
    late_periods: int
    lateness_total_sec: float
    lateness_max_sec: float

    def as_dict(self) -> dict[str, Any]:
        return {
            "function": self.function, "where": self.where, "node": self.node, "entity": self.entity,
            "thread": self.thread, "late_periods": self.late_periods,
            "lateness_total_ms": round(self.lateness_total_sec * 1e3, 3),
            "lateness_max_ms": round(self.lateness_max_sec * 1e3, 3),
        }

    def describe(self) -> str:
        who = f" ({self.entity} of {self.node})" if self.node else (f" in thread {self.thread}" if self.thread else "")
        at = f" at {self.where}" if self.where else ""
        worst = f", worst {self.lateness_max_sec * 1e3:.2f} ms" if self.lateness_max_sec else ""
        return (
            f"{self.function}{who}{at}: {self.late_periods} late period{'s' if self.late_periods != 1 else ''}, "
            f"{self.lateness_total_sec * 1e3:.1f} ms in all{worst}"
        )


def _library_dirs() -> tuple[str, ...]:
    paths = sysconfig.get_paths()
    dirs = {paths.get(k, "") for k in ("stdlib", "platstdlib", "purelib", "platlib")}
    dirs.add(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))  # the aiorobot package
    return tuple(os.path.join(os.path.realpath(d), "") for d in dirs if d)


_LIBRARY_DIRS = _library_dirs()


def _is_user_code(filename: str) -> bool:
    if filename.startswith("<frozen"):
        return False
    return not os.path.realpath(filename).startswith(_LIBRARY_DIRS)


def name_callback(entity: Any) -> tuple[str, str]:
    """``(function, "file:line")`` of an entity's callback (where it is defined)."""
    fn = getattr(entity, "callback", None) or getattr(entity, "handler", None)
    while isinstance(fn, functools.partial):
        fn = fn.func
    fn = inspect.unwrap(fn) if callable(fn) else fn
    code = getattr(getattr(fn, "__func__", fn), "__code__", None)
    if code is None:
        return type(entity).__name__, ""
    return getattr(code, "co_qualname", code.co_name), f"{os.path.basename(code.co_filename)}:{code.co_firstlineno}"


def name_frame(frame: FrameType | None) -> tuple[str, str, str, str]:
    """``(function, "file:line", node, entity)`` for the code running in ``frame``'s thread."""
    if frame is None:
        return NO_PYTHON, "", "", ""
    node, entity, _ = blocked_at(frame)
    chosen = frame
    f: FrameType | None = frame
    while f is not None:
        if _is_user_code(f.f_code.co_filename):
            chosen = f
            break
        f = f.f_back
    code = chosen.f_code
    function = getattr(code, "co_qualname", code.co_name)
    return function, f"{os.path.basename(code.co_filename)}:{chosen.f_lineno}", node, entity


class _Tally:
    __slots__ = ("count", "max_ns", "node", "entity", "thread", "total_ns", "where")

    def __init__(self, where: str, node: str, entity: str, thread: str) -> None:
        self.where, self.node, self.entity, self.thread = where, node, entity, thread
        self.count = self.total_ns = self.max_ns = 0


class LateWatch:
    """Finds the culprits of late periods of one loop's timers (see the module docstring)."""

    def __init__(
        self, late_threshold_sec: float, loop_thread_id: int, loop_name: str = "priority",
        loops: dict[int, str] | None = None,
        recent: Callable[[str, int], tuple[Any, Any, int] | None] | None = None,
    ) -> None:
        self.threshold_ns = round(late_threshold_sec * 1e9)
        self.loop_thread_id = loop_thread_id
        self.loop_name = loop_name
        #: thread id -> loop name of the event-loop threads (the watched one included)
        self.loops = {**(loops or {}), loop_thread_id: loop_name}
        #: ``recent(loop, since_ns)``: the node callback that ran longest on that loop since then
        self._recent = recent
        #: timer key -> its next deadline (monotonic ns), written by the loop's timers
        self._armed: dict[int, int] = {}
        #: timer key -> (deadline, lateness ns) of its last call
        self._fired: dict[int, tuple[int, int]] = {}
        #: timer key -> the entity name of that timer (``timer 0.02s``)
        self._entities: dict[int, str] = {}
        self._wake = threading.Event()
        self._idle = False
        self._closed = False
        self._lock = threading.Lock()
        self._tallies: dict[tuple[str, str], _Tally] = {}
        #: late periods of the loop's timers, and their lateness, whether sampled or not
        self.late_periods = 0
        self._late_ns = 0
        self._attributed = 0
        self._attributed_ns = 0
        self._clock_ids: dict[int, int] = {}
        self._thread = threading.Thread(target=self._main, name="aiorobot-culprit", daemon=True)
        self._thread.start()

    def __repr__(self) -> str:
        return f"<LateWatch {self.loop_name} threshold={self.threshold_ns / 1e6:g}ms late={self.late_periods}>"

    # -- the loop's side (cheap: dict stores) -----------------------------------------------------

    def arm(self, key: int, deadline_ns: int, entity: str = "") -> None:
        """A timer of the loop (``entity``: how ``blocked_at`` names it) waits for ``deadline_ns``."""
        self._armed[key] = deadline_ns
        if entity:
            self._entities[key] = entity
        if self._idle:
            self._wake.set()

    def disarm(self, key: int) -> None:
        self._armed.pop(key, None)
        self._entities.pop(key, None)

    def fired(self, key: int, deadline_ns: int, late_ns: int) -> None:
        """The timer ``key`` started its callback ``late_ns`` after ``deadline_ns``."""
        self._fired[key] = (deadline_ns, late_ns)
        if late_ns > self.threshold_ns:
            self.late_periods += 1
            self._late_ns += late_ns

    def close(self) -> None:
        self._closed = True
        self._wake.set()

    # -- the report --------------------------------------------------------------------------

    def culprits(self, top: int = 5) -> list[Culprit]:
        """The ``top`` causes of late periods, most lateness first; ``(not sampled)`` included."""
        with self._lock:
            tallies = list(self._tallies.items())
            unsampled = self.late_periods - self._attributed
            unsampled_ns = self._late_ns - self._attributed_ns
        found = [
            Culprit(function, t.where, t.node, t.entity, t.thread, t.count, t.total_ns / 1e9, t.max_ns / 1e9)
            for (function, _), t in tallies
        ]
        if unsampled > 0 and unsampled_ns > 0:
            found.append(Culprit(NOT_SAMPLED, "", "", "", "", unsampled, unsampled_ns / 1e9, 0.0))
        found.sort(key=lambda c: c.lateness_total_sec, reverse=True)
        return found[:top]

    # -- the sampler thread ----------------------------------------------------------------------

    def _main(self) -> None:
        last = 0
        previous: tuple[int, dict[int, int]] | None = None
        gap = round(MIN_GAP_SEC * 1e9)
        lead = round(LEAD_SEC * 1e9)
        while not self._closed:
            pick = self._next(last + gap)
            if pick is None:
                self._idle = True
                if self._next(last + gap) is None:  # an arm() between the look and _idle = True
                    self._wake.wait(0.5)
                self._wake.clear()
                self._idle = False
                continue
            key, deadline = pick
            last = deadline
            _sleep_until(deadline - lead)
            now = (time.monotonic_ns(), self._cpu_times())
            # A late read means a thread held the GIL across the lead (a long C call): measure
            # from the previous read instead, which that call's CPU time comes after.
            late_read = now[0] - (deadline - lead) > self.threshold_ns
            before = previous if late_read and previous is not None else now
            previous = now
            _sleep_until(deadline + self.threshold_ns)
            done = self._fired.get(key)
            if done is not None and done[0] >= deadline and (done[0] > deadline or done[1] <= self.threshold_ns):
                continue  # on time (or the timer moved on)
            if self._armed.get(key, deadline) != deadline and (done is None or done[0] < deadline):
                continue  # reset or cancelled meanwhile
            blame = self._sample(before, key, deadline)
            late = self._wait_fired(key, deadline)
            if late is not None and late > self.threshold_ns:
                self._add(blame, late)

    def _next(self, not_before: int) -> tuple[int, int] | None:
        best: tuple[int, int] | None = None
        for key, deadline in list(self._armed.items()):
            if deadline >= not_before and (best is None or deadline < best[1]):
                best = (key, deadline)
        return best

    def _cpu_times(self) -> dict[int, int]:
        times: dict[int, int] = {}
        me = threading.get_ident()
        for ident in sys._current_frames():
            if ident == me:
                continue
            clock = self._clock_ids.get(ident)
            try:
                if clock is None:
                    clock = self._clock_ids[ident] = time.pthread_getcpuclockid(ident)
                times[ident] = time.clock_gettime_ns(clock)
            except OSError:  # the thread ended meanwhile
                self._clock_ids.pop(ident, None)
        if len(self._clock_ids) > 4 * len(times) + 16:  # forget threads long gone
            self._clock_ids = {k: v for k, v in self._clock_ids.items() if k in times}
        return times

    def _sample(self, start: tuple[int, dict[int, int]], key: int, deadline: int) -> tuple[str, str, str, str, str]:
        """``(function, where, node, entity, thread)`` of the thread that ran most since ``start``.

        The watched loop's own thread is passed over once the late timer has fired and what it
        ran is that timer's callback or the loop's own work: that CPU time came after the
        lateness, not before it (a loaded machine delays the sampler too).
        """
        since, before = start
        after = self._cpu_times()
        done = self._fired.get(key)
        fired = done is not None and done[0] >= deadline
        frames = sys._current_frames()
        grown = sorted(((cpu - before.get(ident, cpu), ident) for ident, cpu in after.items()), reverse=True)
        for ran, ident in grown:
            if ran < self.threshold_ns // 4:
                break
            blame = self._name(ident, frames.get(ident), since)
            if fired and ident == self.loop_thread_id and (blame[2] == "" or blame[3] == self._entities.get(key)):
                continue
            return blame
        return NO_PYTHON, "", "", "", ""

    def _name(self, ident: int, frame: FrameType | None, since: int) -> tuple[str, str, str, str, str]:
        loop = self.loops.get(ident)
        if loop is None:
            thread = {t.ident: t.name for t in threading.enumerate()}.get(ident, str(ident))
            return (*name_frame(frame), thread)
        thread = f"{loop} loop"
        if blocked_at(frame)[0]:
            return (*name_frame(frame), thread)
        # the callback returned before the sampler got the GIL: the one that ran longest on that
        # loop meanwhile; with none, the loop's own work (I/O, timers)
        found = self._recent(loop, since) if self._recent is not None else None
        if found is None or found[2] < self.threshold_ns // 4:
            return f"({loop} loop between callbacks)", "", "", "", thread
        from ._node import _describe

        node, entity, _ = found
        function, where = name_callback(entity)
        return function, where, node.get_fully_qualified_name(), _describe(entity), thread

    def _wait_fired(self, key: int, deadline: int) -> int | None:
        """The lateness of the timer's call for ``deadline`` once it has started; None if it never does."""
        give_up = time.monotonic() + _FIRE_WAIT_SEC
        while not self._closed and time.monotonic() < give_up:
            done = self._fired.get(key)
            if done is not None and done[0] >= deadline:
                return done[1] if done[0] == deadline else None
            time.sleep(0.0005)
        return None

    def _add(self, blame: tuple[str, str, str, str, str], late_ns: int) -> None:
        function, where, node, entity, thread = blame
        with self._lock:
            tally = self._tallies.get((function, node))
            if tally is None:
                tally = self._tallies[(function, node)] = _Tally(where, node, entity, thread)
            tally.count += 1
            tally.total_ns += late_ns
            tally.max_ns = max(tally.max_ns, late_ns)
            self._attributed += 1
            self._attributed_ns += late_ns


def _sleep_until(deadline_ns: int) -> None:
    remaining = deadline_ns - time.monotonic_ns()
    if remaining > 0:
        time.sleep(remaining / 1e9)
