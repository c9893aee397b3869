"""Waiting for absolute monotonic deadlines on an event loop.

libuv (and so uvloop) counts timers in whole milliseconds and can fire up to
~0.9 ms early, so a timer that must keep sub-millisecond deadlines needs more:

* :class:`LoopWaker` (the main loop): loop timers, re-checking the clock on every
  wake; late by a fraction of a millisecond, never early.
* :class:`TimerFdWaker` (the priority loop, Linux): one ``timerfd`` armed with the
  absolute ``CLOCK_MONOTONIC`` deadline of the earliest waiter and watched by the
  loop with ``add_reader``. The kernel's high-resolution timer wakes ``epoll``
  within microseconds, the loop stays free for messages meanwhile, and nothing
  spins.
"""

from __future__ import annotations

import asyncio
import ctypes
import ctypes.util
import heapq
import itertools
import math
import os

import sys
import time

__all__ = ["LoopWaker", "TimerFdWaker", "make_waker"]


class LoopWaker:
    """Deadline waits with the loop's own timers (millisecond resolution, never early)."""

    precise = False

    def __init__(self, loop: asyncio.AbstractEventLoop) -> None:
        self._loop = loop

    def add(self, deadline_ns: int, fut: asyncio.Future[None]) -> None:
        """Resolve ``fut`` once the monotonic clock reaches ``deadline_ns`` (unless done before)."""
        remaining = deadline_ns - time.monotonic_ns()
        if remaining <= 0:
            _done(fut)
            return
        # Round up to whole milliseconds: libuv fires early otherwise, and we would spin.
        self._loop.call_later(math.ceil(remaining / 1e6) / 1e3, self._check, deadline_ns, fut)

    def _check(self, deadline_ns: int, fut: asyncio.Future[None]) -> None:
        if not fut.done():
            self.add(deadline_ns, fut)

    async def wait_until_ns(self, deadline_ns: int) -> None:
        fut = self._loop.create_future()
        self.add(deadline_ns, fut)
        await fut

    def close(self) -> None:
        pass


def _done(fut: asyncio.Future[None]) -> None:
    if not fut.done():
        fut.set_result(None)


class _ITimerSpec(ctypes.Structure):
    _fields_ = [
        ("it_interval_sec", ctypes.c_long),
        ("it_interval_nsec", ctypes.c_long),
        ("it_value_sec", ctypes.c_long),
        ("it_value_nsec", ctypes.c_long),
    ]


_CLOCK_MONOTONIC = 1
_TFD_NONBLOCK = 0o4000
_TFD_CLOEXEC = 0o2000000
_TFD_TIMER_ABSTIME = 1
_libc: ctypes.CDLL | None = None


def _load_libc() -> ctypes.CDLL | None:
    global _libc
    if _libc is None and sys.platform.startswith("linux"):
        lib = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6", use_errno=True)
        lib.timerfd_create.argtypes = [ctypes.c_int, ctypes.c_int]
        lib.timerfd_settime.argtypes = [
            ctypes.c_int,
            ctypes.c_int,
            ctypes.POINTER(_ITimerSpec),
            ctypes.c_void_p,
        ]
        _libc = lib
    return _libc


class TimerFdWaker:
    """Sub-millisecond deadline waits through one Linux ``timerfd`` per loop.

    Must be used from the loop's own thread only.
    """

    precise = True

    def __init__(self, loop: asyncio.AbstractEventLoop) -> None:
        libc = _load_libc()
        if libc is None:
            raise OSError("timerfd needs Linux")
        fd = libc.timerfd_create(_CLOCK_MONOTONIC, _TFD_NONBLOCK | _TFD_CLOEXEC)
        if fd < 0:
            err = ctypes.get_errno()
            raise OSError(err, f"timerfd_create failed: {os.strerror(err)}")
        self._libc = libc
        self._fd = fd
        self._loop = loop
        self._heap: list[tuple[int, int, asyncio.Future[None]]] = []
        self._seq = itertools.count()
        self._armed_ns = 0
        loop.add_reader(fd, self._on_fire)

    def _arm(self, deadline_ns: int) -> None:
        sec, nsec = divmod(max(deadline_ns, 1), 1_000_000_000)
        spec = _ITimerSpec(0, 0, sec, nsec)
        if self._libc.timerfd_settime(self._fd, _TFD_TIMER_ABSTIME, ctypes.byref(spec), None) != 0:
            err = ctypes.get_errno()
            raise OSError(err, f"timerfd_settime failed: {os.strerror(err)}")
        self._armed_ns = deadline_ns

    def _on_fire(self) -> None:
        try:
            os.read(self._fd, 8)
        except BlockingIOError:
            pass
        now = time.monotonic_ns()
        heap = self._heap
        while heap and (heap[0][0] <= now or heap[0][2].done()):
            _, _, fut = heapq.heappop(heap)
            if not fut.done():
                fut.set_result(None)
        if heap:
            self._arm(heap[0][0])
        else:
            self._armed_ns = 0

    def add(self, deadline_ns: int, fut: asyncio.Future[None]) -> None:
        """Resolve ``fut`` once the monotonic clock reaches ``deadline_ns`` (unless done before).

        A future finished by someone else stays in the heap until its time and is skipped then.
        """
        if deadline_ns <= time.monotonic_ns():
            _done(fut)
            return
        heapq.heappush(self._heap, (deadline_ns, next(self._seq), fut))
        if self._armed_ns == 0 or deadline_ns < self._armed_ns:
            self._arm(deadline_ns)

    async def wait_until_ns(self, deadline_ns: int) -> None:
        fut = self._loop.create_future()
        self.add(deadline_ns, fut)
        await fut

    def close(self) -> None:
        if self._fd >= 0:
            if not self._loop.is_closed():
                self._loop.remove_reader(self._fd)
            os.close(self._fd)
            self._fd = -1


def make_waker(loop: asyncio.AbstractEventLoop, precise: bool) -> LoopWaker | TimerFdWaker:
    if precise:
        try:
            return TimerFdWaker(loop)
        except OSError:
            pass
    return LoopWaker(loop)


