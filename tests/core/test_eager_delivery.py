"""Eager delivery of a received message (``deliver_eagerly``, and ``EagerBatch``, what the zenoh
transport's drain uses): an idle subscription's plain-function callback runs in the delivering
call, not one loop iteration later in its dispatcher, and everything else is delivered as by any
publish. Every test runs both ways."""

from __future__ import annotations

import asyncio
import logging

from aiorobot import MutuallyExclusiveCallbackGroup, Node, ReentrantCallbackGroup
import pytest

from aiorobot._core._pubsub import EagerBatch, deliver_eagerly
from aiorobot.msgs.std_msgs import Int32
from aiorobot.testing import settle


def _in_a_batch(publish, *args) -> None:
    """One message delivered as a drain delivers each of its messages."""
    with EagerBatch() as batch:
        publish(*args)
        if batch.ready:
            batch.run()


@pytest.fixture(params=[deliver_eagerly, _in_a_batch], ids=["deliver_eagerly", "EagerBatch"])
def deliver(request):
    return request.param


async def _started(runtime, node: Node) -> None:
    await settle(runtime)  # dispatchers started and parked on their queues


async def test_an_idle_plain_callback_runs_within_the_delivery(runtime, deliver) -> None:
    node = runtime.add_node(Node("n"))
    pub = node.create_publisher(Int32, "/x", 10)
    got: list[int] = []
    node.create_subscription(Int32, "/x", got.append, 10)
    await _started(runtime, node)
    for i in range(3):
        deliver(pub.publish, Int32(data=i))
        assert [m.data for m in got] == list(range(i + 1))  # already run: no await since the delivery
    pub.publish(Int32(data=9))  # a plain publish still goes through the dispatcher
    assert len(got) == 3
    await settle(runtime)
    assert [m.data for m in got] == [0, 1, 2, 9]
    sub = node.subscriptions[0]
    assert sub.received == 4 and sub.is_idle() and node._callback_stats[sub].calls == 4  # each counted once


async def test_coroutine_callbacks_and_busy_groups_wait_for_their_dispatcher(runtime, deliver) -> None:
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
        deliver(pub.publish, Int32(data=1))
        assert order == ["plain 1"]
        await settle(runtime)
        assert sorted(order) == ["coro 1", "plain 1"]  # the busy group's waits for it
    await settle(runtime)
    assert sorted(order) == ["busy 1", "coro 1", "plain 1"]


async def test_a_topic_with_a_message_info_subscriber_is_delivered_through_the_dispatchers(runtime, deliver) -> None:
    node = runtime.add_node(Node("n"))
    pub = node.create_publisher(Int32, "/x", 10)
    got: list[tuple[str, int]] = []
    node.create_subscription(Int32, "/x", lambda m, info: got.append(("info", info["reception_sequence_number"])), 10)
    node.create_subscription(Int32, "/x", lambda m: got.append(("plain", m.data)), 10, callback_group=ReentrantCallbackGroup())
    await _started(runtime, node)
    deliver(pub.publish, Int32(data=5))
    assert got == []  # MessageInfo: every subscription of the topic gets the publisher's data, queued
    await settle(runtime)
    assert sorted(got) == [("info", 1), ("plain", 5)]


async def test_what_an_eager_callback_publishes_is_delivered_as_usual_and_in_order(runtime, deliver) -> None:
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
        deliver(pub.publish, Int32(data=i))
        await settle(runtime)
    assert seen == [0, 10, 20, 30, 40]


async def test_a_raising_eager_callback_is_logged_and_the_subscription_goes_on(runtime, caplog, deliver) -> None:
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
            deliver(pub.publish, Int32(data=i))
    assert got == [0, 2] and not group.locked()
    assert "callback of subscription /x of /n raised" in caplog.text and "bad one" in caplog.text


async def test_a_plain_callback_returning_an_awaitable_holds_its_group_until_it_ends(runtime, deliver) -> None:
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
    deliver(pub.publish, Int32(data=1))
    deliver(pub.publish, Int32(data=2))  # the group is held by the first: queued
    for _ in range(5):
        await asyncio.sleep(0)
    assert group.locked() and done == []
    release.set()
    await settle(runtime)
    assert done == [1, 2] and not group.locked() and node.subscriptions[0].is_idle()


async def test_a_reentrant_group_callback_runs_eagerly_too(runtime, deliver) -> None:
    node = runtime.add_node(Node("n"))
    pub = node.create_publisher(Int32, "/x", 10)
    got: list[int] = []
    node.create_subscription(Int32, "/x", lambda m: got.append(m.data), 10, callback_group=ReentrantCallbackGroup())
    await _started(runtime, node)
    deliver(pub.publish, Int32(data=7))
    assert got == [7]


async def test_a_delivery_that_raises_leaves_what_it_queued_to_the_dispatchers(runtime, deliver) -> None:
    node = runtime.add_node(Node("n"))
    pub = node.create_publisher(Int32, "/x", 10)
    got: list[int] = []
    node.create_subscription(Int32, "/x", lambda m: got.append(m.data), 10)
    await _started(runtime, node)

    def publish_then_interrupted(msg: Int32) -> None:
        pub.publish(msg)
        raise KeyboardInterrupt  # (a Ctrl-C landing in the delivery)

    try:
        deliver(publish_then_interrupted, Int32(data=4))
    except KeyboardInterrupt:
        pass
    assert got == []  # not run in the interrupted delivery, but not stranded either
    await settle(runtime)
    assert got == [4]


async def test_a_batch_runs_each_message_s_callbacks_before_publishing_the_next(runtime) -> None:
    node = runtime.add_node(Node("n"))
    pub = node.create_publisher(Int32, "/x", 10)
    other = node.create_publisher(Int32, "/y", 10)
    order: list[str] = []

    def on_x(m: Int32) -> None:
        order.append(f"x {m.data}")
        other.publish(Int32(data=m.data))  # not delivered eagerly: the dispatcher of /y takes it

    node.create_subscription(Int32, "/x", on_x, 10)
    node.create_subscription(Int32, "/x", lambda m: order.append(f"x' {m.data}"), 10)
    node.create_subscription(Int32, "/y", lambda m: order.append(f"y {m.data}"), 10)
    await _started(runtime, node)
    with EagerBatch() as batch:
        for i in range(3):
            pub.publish(Int32(data=i))
            if batch.ready:
                batch.run()
            assert order[-2:] == [f"x {i}", f"x' {i}"]  # both ran before the next message
    assert not any(o.startswith("y") for o in order)
    await settle(runtime)
    assert [o for o in order if o.startswith("y")] == ["y 0", "y 1", "y 2"]


async def test_an_interrupted_batch_callback_leaves_the_others_to_their_dispatchers(runtime) -> None:
    node = runtime.add_node(Node("n"))
    pub = node.create_publisher(Int32, "/x", 10)
    got: list[str] = []

    def interrupted(m: Int32) -> None:
        got.append("first")
        raise KeyboardInterrupt  # (a Ctrl-C landing in the callback)

    node.create_subscription(Int32, "/x", interrupted, 10)
    node.create_subscription(Int32, "/x", lambda m: got.append("second"), 10)
    await _started(runtime, node)
    with pytest.raises(KeyboardInterrupt):
        with EagerBatch() as batch:
            pub.publish(Int32(data=1))
            batch.run()
    assert got == ["first"]  # the second was not run in the interrupted batch, but not stranded either
    await settle(runtime)
    assert got == ["first", "second"]
