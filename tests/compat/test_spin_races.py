"""Races between threads that spin a context and threads that wake it or block on it (issue 25 item 8).

ros2/examples' service_member_function.py and client_async_member_function.py in one process
(one node spun in a thread, the other's blocking calls in the main thread) could stay running:
a wake from another thread could be lost, and a blocking call made while another thread
started to spin raised or waited on work queued where that thread's loop did not look. Each
test forces one interleaving.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Iterator

import pytest

from aiorobot.compat import rclpy
from aiorobot.compat.rclpy.context import Context
from aiorobot.compat.rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
from aiorobot.msgs.example_interfaces import AddTwoInts


@pytest.fixture
def context() -> Iterator[Context]:
    context = Context()
    rclpy.init(context=context)
    try:
        yield context
    finally:
        rclpy.try_shutdown(context=context)


def test_a_wake_between_the_spins_check_and_its_sleep_is_not_lost(context):
    met = threading.Event()

    def done() -> bool:
        if not met.is_set():
            # another thread meets the condition and wakes the spin right after it looked
            waker = threading.Thread(target=lambda: (met.set(), context.wake()))
            waker.start()
            waker.join()
            return False
        return True

    results: list[bool] = []
    spinner = threading.Thread(target=lambda: results.append(context.spin_until(None, done, None, raise_on_shutdown=False)))
    spinner.start()
    spinner.join(10)
    woken = not spinner.is_alive()
    if not woken:  # the wake was lost: release the spin before failing
        context.wake()
        spinner.join(10)
    assert woken, "the spin slept on after the wake that met its condition"
    assert results == [True]


class _TakenRightAfterTheLook:
    """The context's spin lock, taken by a spinner thread right after the main thread looked at it."""

    def __init__(self, real: threading.Lock, take: object) -> None:
        self._real = real
        self._take = take
        self._fired = False

    def locked(self) -> bool:
        was = self._real.locked()
        if not self._fired and threading.current_thread() is threading.main_thread():
            self._fired = True
            self._take()  # type: ignore[operator]
        return was

    def acquire(self, blocking: bool = True, timeout: float = -1) -> bool:
        return self._real.acquire(blocking, timeout)

    def release(self) -> None:
        self._real.release()


def test_a_blocking_call_as_another_thread_starts_spinning_waits_beside_it(context):
    server = rclpy.create_node("add_server", context=context)
    server.create_service(AddTwoInts, "add", lambda request, response: response)
    client = rclpy.create_node("add_client", context=context).create_client(AddTwoInts, "add")
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(server)

    def spin() -> None:
        try:
            executor.spin()
        except ExternalShutdownException:
            pass

    spinner = threading.Thread(target=spin)
    real = context._spin_lock

    def take() -> None:
        spinner.start()
        deadline = time.monotonic() + 10
        while not (real.locked() and context.loop is not None and context.loop.is_running()):
            assert time.monotonic() < deadline, "the spinner thread never ran the loop"
            time.sleep(0.001)

    context._spin_lock = _TakenRightAfterTheLook(real, take)  # type: ignore[assignment]
    try:
        # rclpy's blocking call: before, "the executor is already spinning in another thread"
        assert client.wait_for_service(timeout_sec=5.0) is True
    finally:
        executor.shutdown()
        spinner.join(10)
        context._spin_lock = real
    assert not spinner.is_alive()
