"""aiorobot.Future against rclpy's own Future tests (ros2/rclpy rclpy/test/test_task.py::TestFuture)."""

import asyncio
import threading

import pytest

from aiorobot import Future
from aiorobot._core._future import future_of


def test_cancelled():
    # rclpy test_task.py::TestFuture::test_cancelled
    f = Future()
    f.cancel()
    assert f.cancelled() and f.done() and f.result() is None


def test_done():
    # rclpy test_task.py::TestFuture::test_done
    f = Future()
    assert not f.done()
    f.set_result(None)
    assert f.done()


def test_set_result():
    # rclpy test_task.py::TestFuture::test_set_result
    f = Future()
    f.set_result("Sentinel Result")
    assert f.result() == "Sentinel Result" and f.done()


def test_set_exception():
    # rclpy test_task.py::TestFuture::test_set_exception
    f = Future()
    f.set_exception(RuntimeError("Sentinel Exception"))
    assert str(f.exception()) == "Sentinel Exception" and f.done()
    with pytest.raises(RuntimeError, match="Sentinel Exception"):
        f.result()


def test_await_driven_by_hand():
    # rclpy test_task.py::TestFuture::test_await
    f = Future()

    async def coro():
        return await f

    c = coro()
    c.send(None)
    f.set_result("Sentinel Result")
    with pytest.raises(StopIteration) as stop:
        c.send(None)
    assert stop.value.value == "Sentinel Result"


def test_await_exception_driven_by_hand():
    # rclpy test_task.py::TestFuture::test_await_exception
    f = Future()

    async def coro():
        return await f

    c = coro()
    c.send(None)
    f.set_exception(RuntimeError("test exception"))
    with pytest.raises(RuntimeError):
        c.send(None)


@pytest.mark.parametrize("finish", ["cancel", "set_result", "set_exception"])
def test_finishing_invokes_callbacks(finish):
    # rclpy test_task.py::TestFuture::test_cancel_invokes_callbacks, ::test_set_result_invokes_callbacks,
    # ::test_set_exception_invokes_callbacks
    called = []
    f = Future()
    f.add_done_callback(called.append)
    if finish == "cancel":
        f.cancel()
    elif finish == "set_result":
        f.set_result("Anything")
    else:
        f.set_exception(ValueError("Anything"))
    assert called == [f]


def test_add_done_callback_invokes_callback():
    # rclpy test_task.py::TestFuture::test_add_done_callback_invokes_callback
    called = []
    f = Future()
    f.set_result("Anything")
    f.add_done_callback(called.append)
    assert called == [f]


async def test_on_a_loop_done_callbacks_are_scheduled_in_order():
    # rclpy test_task.py::TestFuture::test_set_result_schedules_callbacks (the loop is the executor)
    order = []
    f = Future()
    f.add_done_callback(lambda fut: order.append(("a", fut.result())))
    f.add_done_callback(lambda fut: order.append(("b", fut.result())))
    f.set_result(7)
    assert order == []  # scheduled, not run inline
    await asyncio.sleep(0)
    assert order == [("a", 7), ("b", 7)]


async def test_await_on_a_loop_and_from_another_thread():
    f = Future()
    threading.Thread(target=f.set_result, args=("from a thread",)).start()
    assert await asyncio.wait_for(f, 10) == "from a thread"


async def test_awaiting_a_cancelled_future_raises_cancelled_error():
    f = Future()
    waiter = asyncio.ensure_future(f)
    await asyncio.sleep(0)
    assert f.cancel() is True and f.cancel() is False
    with pytest.raises(asyncio.CancelledError):
        await waiter


async def test_future_of_mirrors_the_task_and_cancel_cancels_it():
    started = asyncio.Event()

    async def forever():
        started.set()
        await asyncio.Event().wait()

    f = future_of(forever())
    await started.wait()
    f.cancel()
    await asyncio.sleep(0)
    assert f.cancelled()

    async def boom():
        raise ValueError("nope")

    g = future_of(boom())
    with pytest.raises(ValueError, match="nope"):
        await g
    assert isinstance(g.exception(), ValueError)


def test_future_of_needs_a_loop():
    async def nothing():
        pass

    with pytest.raises(RuntimeError, match="no event loop"):
        future_of(nothing())
