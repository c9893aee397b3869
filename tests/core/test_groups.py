"""Callback groups: exclusive groups serialise callbacks across awaits; reentrant ones overlap."""

import asyncio

import pytest

from aiorobot import MutuallyExclusiveCallbackGroup, Node, ReentrantCallbackGroup
from aiorobot.msgs.std_msgs import Int32
from aiorobot.testing import settle


async def _run_two(runtime, group_a, group_b):
    node = runtime.add_node(Node("n"))
    pub_a = node.create_publisher(Int32, "/a", 10)
    pub_b = node.create_publisher(Int32, "/b", 10)
    gate = asyncio.Event()
    log = []

    async def on_a(msg):
        log.append("a start")
        await gate.wait()
        log.append("a end")

    async def on_b(msg):
        log.append("b")

    node.create_subscription(Int32, "/a", on_a, 10, callback_group=group_a)
    node.create_subscription(Int32, "/b", on_b, 10, callback_group=group_b)
    pub_a.publish(Int32())
    await settle(runtime)
    pub_b.publish(Int32())
    await settle(runtime)
    before_release = list(log)
    gate.set()
    await settle(runtime)
    return before_release, log


async def test_mutually_exclusive_group_holds_across_awaits(runtime):
    group = MutuallyExclusiveCallbackGroup()
    before, after = await _run_two(runtime, group, group)
    assert before == ["a start"]
    assert after == ["a start", "a end", "b"]


async def test_default_group_is_mutually_exclusive(runtime):
    before, after = await _run_two(runtime, None, None)
    assert before == ["a start"]


async def test_separate_groups_run_concurrently(runtime):
    before, after = await _run_two(runtime, MutuallyExclusiveCallbackGroup(), MutuallyExclusiveCallbackGroup())
    assert before == ["a start", "b"]


async def test_reentrant_callback_overlaps_with_itself(runtime):
    node = runtime.add_node(Node("n"))
    pub = node.create_publisher(Int32, "/a", 10)
    gate = asyncio.Event()
    active = []
    peak = []

    async def cb(msg):
        active.append(msg.data)
        peak.append(len(active))
        await gate.wait()
        active.remove(msg.data)

    node.create_subscription(Int32, "/a", cb, 10, callback_group=ReentrantCallbackGroup())
    for i in range(4):
        pub.publish(Int32(data=i))
    await settle(runtime)
    assert max(peak) == 4
    gate.set()
    await settle(runtime)
    assert active == []


async def test_group_is_an_async_context_manager():
    group = MutuallyExclusiveCallbackGroup()
    async with group:
        assert group.locked()
    assert not group.locked()
    async with ReentrantCallbackGroup():
        pass


async def test_the_group_lock_is_handed_to_its_waiters_in_order_and_a_cancelled_waiter_passes_it_on():
    """The exclusive group's lock: free, it is taken without waiting; on release it goes to the
    longest waiter (a steady stream cannot overtake one that waits), and a waiter cancelled before
    or after it was handed the lock does not keep it."""
    from aiorobot._core._groups import GroupLock

    lock = GroupLock()
    order: list[int] = []

    async def take(i: int) -> None:
        await lock.acquire()
        order.append(i)
        lock.release()

    assert lock.try_acquire() and lock.locked()
    tasks = [asyncio.create_task(take(i)) for i in range(4)]
    await asyncio.sleep(0)  # all four wait
    assert not lock.try_acquire()  # held, and others wait before any newcomer
    tasks[1].cancel()  # cancelled while waiting
    lock.release()  # handed to 0; 0 hands it to 2
    await asyncio.sleep(0)
    tasks[3].cancel()  # may have been handed the lock already: it must pass it on
    await asyncio.gather(*tasks, return_exceptions=True)
    assert order[:2] == [0, 2] and 1 not in order
    assert not lock.locked() and lock.try_acquire()
    lock.release()
    with pytest.raises(RuntimeError, match="not held"):
        lock.release()


async def test_an_exclusive_group_class_of_ones_own_is_entered_around_each_callback(runtime):
    from aiorobot import CallbackGroup

    class Logged(CallbackGroup):
        exclusive = True

        def __init__(self) -> None:
            self.lock = asyncio.Lock()
            self.entered = 0

        async def __aenter__(self) -> None:
            await self.lock.acquire()
            self.entered += 1

        async def __aexit__(self, *exc: object) -> None:
            self.lock.release()

    group = Logged()
    before, after = await _run_two(runtime, group, group)
    assert before == ["a start"]  # b waits for a's group, as with the stock exclusive group
    assert after == ["a start", "a end", "b"] and group.entered == 2
