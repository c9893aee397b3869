"""Offloading: process pool for picklable work, thread pool for GIL-releasing kernels."""

import os
import threading

import numpy as np
import pytest

from aiorobot import Node


def _pid_and_sum(values):
    return os.getpid(), float(np.sum(values))


async def test_offload_runs_in_another_process(runtime):
    node = runtime.add_node(Node("n"))
    pid, total = await node.offload(_pid_and_sum, np.arange(10.0))
    assert pid != os.getpid() and total == 45.0


async def test_offload_from_the_priority_loop(runtime):
    node = runtime.add_node(Node("p"), executor="priority")
    result = await runtime.priority_loop.run(node.offload(_pid_and_sum, [1.0, 2.0]))
    assert result[1] == 3.0


async def test_offload_propagates_the_exception(runtime):
    node = runtime.add_node(Node("n"))
    with pytest.raises(ZeroDivisionError):
        await node.offload(divmod, 1, 0)


async def test_run_in_thread_uses_a_worker_thread(runtime):
    node = runtime.add_node(Node("n"))
    ident = await node.run_in_thread(threading.get_ident)
    assert ident != threading.get_ident()


async def test_offload_needs_a_runtime():
    with pytest.raises(RuntimeError, match="not added to a runtime"):
        await Node("n").offload(abs, -1)


def _segments():
    """This process tree's shared-memory segments (Python names them psm_*)."""
    return {name for name in os.listdir("/dev/shm") if name.startswith("psm_")}


def _invert(image):
    return 255 - image


def _fail_after_receiving(image):
    raise ValueError(f"bad frame of shape {image.shape}")


def _slow_big(seconds, started_marker):
    import pathlib
    import time

    pathlib.Path(started_marker).touch()
    time.sleep(seconds)
    return np.ones((512, 512), dtype=np.float64)


@pytest.fixture
def no_leaked_segments():
    before = _segments()
    yield
    assert _segments() - before == set()


async def test_large_arrays_round_trip_through_shared_memory(runtime, no_leaked_segments):
    node = runtime.add_node(Node("n"))
    rng = np.random.default_rng(7)
    image = rng.integers(0, 256, (480, 640, 3), dtype=np.uint8)
    out = await node.offload(_invert, image)
    assert out.dtype == np.uint8 and out.shape == (480, 640, 3)
    np.testing.assert_array_equal(out, 255 - image)
    strided = rng.standard_normal((600, 400))[::2, ::3]  # non-contiguous input
    np.testing.assert_array_equal(await node.offload(np.negative, strided), -strided)


async def test_message_with_a_large_array_field_round_trips(runtime, no_leaked_segments):
    from aiorobot.msgs.sensor_msgs import Image

    node = runtime.add_node(Node("n"))
    data = np.arange(480 * 640 * 3, dtype=np.uint32).astype(np.uint8)
    msg = Image(height=480, width=640, encoding="rgb8", step=1920, data=data)
    assert await node.offload(copy_of, msg) == msg


def copy_of(value):
    return value


async def test_failed_call_leaks_no_shared_memory(runtime, no_leaked_segments):
    node = runtime.add_node(Node("n"))
    with pytest.raises(ValueError, match=r"bad frame of shape \(256, 256\)"):
        await node.offload(_fail_after_receiving, np.zeros((256, 256), dtype=np.float64))


async def test_abandoned_call_frees_its_result_segment(no_leaked_segments, tmp_path):
    import asyncio

    from aiorobot import Runtime

    marker = tmp_path / "started"
    async with Runtime(process_workers=1, handle_signals=False) as rt:
        node = rt.add_node(Node("n"))
        call = asyncio.ensure_future(node.offload(_slow_big, 0.2, str(marker)))
        async with asyncio.timeout(60):  # generous: wait for the worker to report it started
            while not marker.exists():
                await asyncio.sleep(0.01)
        call.cancel()  # the worker goes on and returns a shared-memory result nobody awaits
        with pytest.raises(asyncio.CancelledError):
            await call
        assert await node.offload(abs, -2) == 2  # one worker: the abandoned call has finished
