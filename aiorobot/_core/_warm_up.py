"""Compiling a node's Numba kernels before its first callback, with one line of progress.

A ``cache=True`` kernel compiles on its first call after installing (seconds: the EKF's two
kernels take 5-8 s on the 2-core VM) and loads from its cache on the first call of every later
process (tens of milliseconds). Either cost, paid inside a callback, holds that callback's loop:
on the priority loop it is a stall that the watchdog reports with Numba's type-inference stack.
So a node that uses kernels calls :func:`compile_kernels` at construction, before any loop runs
its callbacks, with calls that exercise every kernel *with the argument types its callbacks
pass* (dtype, dimensions, layout and read-only-ness each select a separate compiled version).

Who sees what: the node's logger prints ``compiling kernels (first run only) ...`` once the
calls have taken ``announce_after_sec`` (a cache load never does), and the elapsed time when
they finish; nothing at all on a warm cache.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from typing import Any

__all__ = ["compile_kernels"]

#: a cache load takes tens of milliseconds; a compile takes seconds
ANNOUNCE_AFTER_SEC = 0.5


def compile_kernels(logger: Any, *calls: Callable[[], object], announce_after_sec: float = ANNOUNCE_AFTER_SEC) -> float:
    """Run ``calls`` (each compiles or loads kernels) now, in this thread; return the seconds taken.

    ``logger`` is a node's logger (anything with ``info``): when the calls outlast
    ``announce_after_sec`` it says so while they run, then how long they took.
    """
    announced = threading.Event()

    def announce() -> None:
        announced.set()
        logger.info("compiling kernels (first run only) ...")

    timer = threading.Timer(announce_after_sec, announce)
    timer.daemon = True
    start = time.perf_counter()
    timer.start()
    try:
        for call in calls:
            call()
    finally:
        timer.cancel()
        timer.join()  # an announcement under way finishes before the closing line
        elapsed = time.perf_counter() - start
    if announced.is_set():
        logger.info(f"compiling kernels (first run only) ... {elapsed:.1f} s")
    return elapsed
