"""Eager delivery of a received message (``deliver_eagerly``, what a transport's drain uses): an
idle subscription's plain-function callback runs in the delivering call, not one loop iteration
later in its dispatcher, and everything else is delivered as by any publish."""

from __future__ import annotations

import asyncio
import logging

from aiorobot import MutuallyExclusiveCallbackGroup, Node, ReentrantCallbackGroup
from aiorobot._core._pubsub import deliver_eagerly
from aiorobot.msgs.std_msgs import Int32
from aiorobot.testing import settle


async def _started(runtime, node: Node) -> None:
    await settle(runtime)  # dispatchers started and parked on their queues


async def test_an_idle_plain_callback_runs_within_the_delivery(runtime) -> None:
    node = runtime.add_node(Node("n"))
    pub = node.create_publisher(Int32, "/x", 10)
    got: list[int] = []
    node.create_subscription(Int32, "/x", got.append, 10)
    await _started(runtime, node)
    for i in range(3):
        deliver_eagerly(pub.publish, Int32(data=i))
        assert [m.data for m in got] == list(range(i + 1))  # already run: no await since the delivery
    pub.publish(Int32(data=9))  # a plain publish still goes through the dispatcher
    assert len(got) == 3
    await settle(runtime)
    assert [m.data for m in got] == [0, 1, 2, 9]
    sub = node.subscriptions[0]
    assert sub.received == 4 and sub.is_idle() and node._callback_stats[sub].calls == 4  # each counted once


async def test_coroutine_callbacks_and_busy_groups_wait_for_their_dispatcher(runtime) -> None:
    node = runtime.add_node(Node("n"))
    pub = node.create_publisher(Int32, "/x", 10)
    order: list[str] = []

    async def coro(m: Int32) -> None:
        order.append(f"coro {m.data}")

    busy = MutuallyExclusiveCallbackGroup()
    node.create_subscription(Int32, "/x", coro, 10, callback_group=ReentrantCallbackGroup())
    node.create_subscription(Int32, "/x", lambda m: order.append(f"busy {m.data}"), 10, callback_group=busy)
    node.create_subscription(Int32, "/x", lambda m: order.append(f"plain {m.data}"), 10)
    await _started(runtime, node)
    async with busy:
        deliver_eagerly(pub.publish, Int32(data=1))
        assert order == ["plain 1"]
        await settle(runtime)
        assert sorted(order) == ["coro 1", "plain 1"]  # the busy group's waits for it
    await settle(runtime)
    assert sorted(order) == ["busy 1", "coro 1", "plain 1"]


async def test_a_topic_with_a_message_info_subscriber_is_delivered_through_the_dispatchers(runtime) -> None:
    node = runtime.add_node(Node("n"))
    pub = node.create_publisher(Int32, "/x", 10)
    got: list[tuple[str, int]] = []
    node.create_subscription(Int32, "/x", lambda m, info: got.append(("info", info["reception_sequence_number"])), 10)
    node.create_subscription(Int32, "/x", lambda m: got.append(("plain", m.data)), 10, callback_group=ReentrantCallbackGroup())
    await _started(runtime, node)
    deliver_eagerly(pub.publish, Int32(data=5))
    assert got == []  # MessageInfo: every subscription of the topic gets the publisher's data, queued
    await settle(runtime)
    assert sorted(got) == [("info", 1), ("plain", 5)]


async def test_what_an_eager_callback_publishes_is_delivered_as_usual_and_in_order(runtime) -> None:
    node = runtime.add_node(Node("relay"))
    pub = node.create_publisher(Int32, "/in", 10)
    out = node.create_publisher(Int32, "/out", 10)
    seen: list[int] = []

    def relay(m: Int32) -> None:
        out.publish(Int32(data=m.data * 10))
        assert seen == [x * 10 for x in range(m.data)]  # not run inside this callback

    node.create_subscription(Int32, "/in", relay, 10)
    node.create_subscription(Int32, "/out", lambda m: seen.append(m.data), 10)
    await _started(runtime, node)
    for i in range(5):
        deliver_eagerly(pub.publish, Int32(data=i))
        await settle(runtime)
    assert seen == [0, 10, 20, 30, 40]


async def test_a_raising_eager_callback_is_logged_and_the_subscription_goes_on(runtime, caplog) -> None:
    node = runtime.add_node(Node("n"))
    pub = node.create_publisher(Int32, "/x", 10)
    got: list[int] = []
    group = MutuallyExclusiveCallbackGroup()

    def cb(m: Int32) -> None:
        if m.data == 1:
            raise ValueError("bad one")
        got.append(m.data)

    node.create_subscription(Int32, "/x", cb, 10, callback_group=group)
    await _started(runtime, node)
    with caplog.at_level(logging.ERROR):
        for i in range(3):
            deliver_eagerly(pub.publish, Int32(data=i))
    assert got == [0, 2] and not group.locked()
    assert "callback of subscription /x of /n raised" in caplog.text and "bad one" in caplog.text


async def test_a_plain_callback_returning_an_awaitable_holds_its_group_until_it_ends(runtime) -> None:
    node = runtime.add_node(Node("n"))
    pub = node.create_publisher(Int32, "/x", 10)
    group = MutuallyExclusiveCallbackGroup()
    release = asyncio.Event()
    done: list[int] = []

    async def work(m: Int32) -> None:
        await release.wait()
        done.append(m.data)

    node.create_subscription(Int32, "/x", lambda m: work(m), 10, callback_group=group)
    await _started(runtime, node)
    deliver_eagerly(pub.publish, Int32(data=1))
    deliver_eagerly(pub.publish, Int32(data=2))  # the group is held by the first: queued
    for _ in range(5):
        await asyncio.sleep(0)
    assert group.locked() and done == []
    release.set()
    await settle(runtime)
    assert done == [1, 2] and not group.locked() and node.subscriptions[0].is_idle()


async def test_a_reentrant_group_callback_runs_eagerly_too(runtime) -> None:
    node = runtime.add_node(Node("n"))
    pub = node.create_publisher(Int32, "/x", 10)
    got: list[int] = []
    node.create_subscription(Int32, "/x", lambda m: got.append(m.data), 10, callback_group=ReentrantCallbackGroup())
    await _started(runtime, node)
    deliver_eagerly(pub.publish, Int32(data=7))
    assert got == [7]


async def test_a_delivery_that_raises_leaves_what_it_queued_to_the_dispatchers(runtime) -> None:
    node = runtime.add_node(Node("n"))
    pub = node.create_publisher(Int32, "/x", 10)
    got: list[int] = []
    node.create_subscription(Int32, "/x", lambda m: got.append(m.data), 10)
    await _started(runtime, node)

    def publish_then_interrupted(msg: Int32) -> None:
        pub.publish(msg)
        raise KeyboardInterrupt  # (a Ctrl-C landing in the delivery)

    try:
        deliver_eagerly(publish_then_interrupted, Int32(data=4))
    except KeyboardInterrupt:
        pass
    assert got == []  # not run in the interrupted delivery, but not stranded either
    await settle(runtime)
    assert got == [4]
