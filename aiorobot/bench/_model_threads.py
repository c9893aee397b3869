"""Executor model ``threads``: rclpy's MultiThreadedExecutor with callback groups.

A faithful, stripped-down copy of how rclpy runs timers on a
``MultiThreadedExecutor(num_threads=4)``:

- one spinning thread builds the wait set from the timers whose callback group
  can execute, waits until the earliest deadline or until a callback ends (the
  executor's guard condition), then takes each ready timer: the group's
  ``beginning_execution`` marks it busy, the timer is "called" (rcl advances its
  deadline, skipping missed periods) and the callback is submitted to a
  ``ThreadPoolExecutor`` of 4 threads;
- when the callback returns, ``ending_execution`` frees the group and the guard
  condition wakes the spinning thread;
- control and perception each have their own ``MutuallyExclusiveCallbackGroup``,
  the configuration the seed recommends.

It leaves out rclpy's own Python overhead per wake (rebuilding the wait set,
taking handles), so it is, if anything, kinder to the thread model than rclpy.
Python's switch interval stays at its default (5 ms), as under rclpy.
"""

from __future__ import annotations

import sys
import threading
import time
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor

from ._model_single import next_deadline
from ._seedconfig import SeedConfig
from ._workload import work_function

__all__ = ["MultiThreadedExecutorModel", "MutuallyExclusiveGroup", "run_threads"]

PYTHON_DEFAULT_SWITCH_INTERVAL_SEC = 0.005


class MutuallyExclusiveGroup:
    """rclpy's ``MutuallyExclusiveCallbackGroup``: one callback of the group at a time."""

    def __init__(self) -> None:
        self._lock = threading.Lock()

    def can_execute(self) -> bool:
        return not self._lock.locked()

    def beginning_execution(self) -> bool:
        return self._lock.acquire(blocking=False)

    def ending_execution(self) -> None:
        self._lock.release()


class _Timer:
    def __init__(self, period_sec: float, callback: Callable[[], None], group: MutuallyExclusiveGroup) -> None:
        self.period_sec = period_sec
        self.callback = callback
        self.group = group
        self.deadline = time.perf_counter() + period_sec


class MultiThreadedExecutorModel:
    """The spin loop of rclpy's ``MultiThreadedExecutor`` for timers."""

    def __init__(self, num_threads: int = 4) -> None:
        self._pool = ThreadPoolExecutor(max_workers=num_threads, thread_name_prefix="bench-threads")
        self._guard = threading.Condition()
        self._timers: list[_Timer] = []
        self._stop = threading.Event()

    def create_timer(self, period_sec: float, callback: Callable[[], None], group: MutuallyExclusiveGroup) -> None:
        self._timers.append(_Timer(period_sec, callback, group))

    def request_stop(self) -> None:
        self._stop.set()
        with self._guard:
            self._guard.notify_all()

    def _execute(self, timer: _Timer) -> None:
        try:
            timer.callback()
        finally:
            timer.group.ending_execution()
            with self._guard:
                self._guard.notify_all()  # the executor's guard condition

    def spin(self) -> None:
        """Spin on the calling thread until :meth:`request_stop`; then drain the pool."""
        try:
            while not self._stop.is_set():
                with self._guard:
                    now = time.perf_counter()
                    waitable = [t for t in self._timers if t.group.can_execute()]
                    ready = [t for t in waitable if t.deadline <= now]
                    if not ready:
                        timeout = min((t.deadline - now for t in waitable), default=None)
                        self._guard.wait(timeout)
                        continue
                for timer in ready:
                    if timer.group.beginning_execution():
                        timer.deadline = next_deadline(timer.deadline, timer.period_sec, time.perf_counter())
                        self._pool.submit(self._execute, timer)
        finally:
            self._pool.shutdown(wait=True)


def run_threads(kind: str, cfg: SeedConfig, num_threads: int = 4) -> list[float]:
    """Run the model; returns the control callback's start stamps in seconds."""
    work = work_function(kind)
    executor = MultiThreadedExecutorModel(num_threads)
    stamps: list[float] = []

    def control() -> None:
        stamps.append(time.perf_counter())
        if len(stamps) >= cfg.stamps_needed:
            executor.request_stop()

    def perception() -> None:
        work(cfg.work_sec)

    executor.create_timer(cfg.control_period_sec, control, MutuallyExclusiveGroup())
    executor.create_timer(cfg.perception_period_sec, perception, MutuallyExclusiveGroup())
    saved = sys.getswitchinterval()
    sys.setswitchinterval(PYTHON_DEFAULT_SWITCH_INTERVAL_SEC)
    try:
        executor.spin()
    finally:
        sys.setswitchinterval(saved)
    return stamps
