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
