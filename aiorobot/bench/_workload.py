"""The perception work of the seed experiment, and a busy main-loop workload.

Module-level functions, so a process pool can pickle them by reference.

- ``sleep_work``: ``time.sleep`` as the seed's rclpy script does. It releases the
  GIL, so threads hide it well.
- ``cpu_work``: pure-Python arithmetic for the same wall time. It holds the GIL,
  which is what real Python perception code does.
"""

from __future__ import annotations

import time

__all__ = ["KINDS", "cpu_work", "python_chunk", "sleep_work", "work_function"]

KINDS = ("sleep", "cpu")


def sleep_work(duration_sec: float) -> float:
    """Sleep for ``duration_sec`` (releases the GIL); returns the time spent."""
    t0 = time.perf_counter()
    time.sleep(duration_sec)
    return time.perf_counter() - t0


def cpu_work(duration_sec: float) -> float:
    """Pure-Python integer arithmetic for ``duration_sec`` of wall time (holds the GIL).

    Returns the time spent. The clock is read every 200 iterations (~10 us), so
    the call overshoots by at most that much.
    """
    t0 = time.perf_counter()
    end = t0 + duration_sec
    x = 1
    while time.perf_counter() < end:
        for i in range(200):
            x = (x * 31 + i) % 1_000_003
    return time.perf_counter() - t0


def python_chunk(duration_sec: float) -> int:
    """Pure-Python arithmetic for ``duration_sec``: one slice of a busy event loop."""
    end = time.perf_counter() + duration_sec
    x = 1
    n = 0
    while time.perf_counter() < end:
        for i in range(50):
            x = (x * 31 + i) % 1_000_003
        n += 1
    return n


def work_function(kind: str):  # -> Callable[[float], float]
    """The work function of a perception kind (``"sleep"`` or ``"cpu"``)."""
    if kind == "sleep":
        return sleep_work
    if kind == "cpu":
        return cpu_work
    raise ValueError(f"perception kind must be one of {KINDS}, received {kind!r}")
