"""Callback groups: exclusive groups serialise callbacks across awaits; reentrant ones overlap."""

import asyncio

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
