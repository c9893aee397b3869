"""Topics in one process: zero-copy delivery, queues, iteration, QoS history and matching."""

import asyncio
import logging

import pytest

from aiorobot import (
    DurabilityPolicy,
    HistoryPolicy,
    Node,
    QoSIncompatibleError,
    QoSProfile,
    ReliabilityPolicy,
    Runtime,
)
from aiorobot.msgs.std_msgs import Int32, String
from aiorobot.testing import settle, wait_for_message

TRANSIENT = QoSProfile(durability=DurabilityPolicy.TRANSIENT_LOCAL, depth=3)


async def test_subscriber_receives_the_published_object(runtime):
    got = []
    pub_node = runtime.add_node(Node("pub"))
    sub_node = runtime.add_node(Node("sub"))
    pub = pub_node.create_publisher(String, "/chatter", 10)
    sub_node.create_subscription(String, "/chatter", got.append, 10)
    msg = String(data="hello")
    pub.publish(msg)
    await settle(runtime)
    assert got == [msg] and got[0] is not msg  # a read-only twin: the publisher may reuse msg


async def test_async_callbacks_run_in_publish_order(runtime):
    got = []

    async def cb(msg):
        await asyncio.sleep(0)
        got.append(msg.data)

    node = runtime.add_node(Node("n"))
    pub = node.create_publisher(Int32, "/x", 100)
    node.create_subscription(Int32, "/x", cb, 100)
    for i in range(50):
        pub.publish(Int32(data=i))
    await settle(runtime)
    assert got == list(range(50))


async def test_keep_last_drops_oldest_when_full(runtime):
    node = runtime.add_node(Node("n"))
    pub = node.create_publisher(Int32, "/x", 10)
    stream = node.subscribe(Int32, "/x", 3)
    for i in range(5):
        pub.publish(Int32(data=i))
    got = [(await anext(stream)).data for _ in range(3)]
    assert got == [2, 3, 4]
    assert stream.subscription.dropped == 2
    stream.close()


async def test_keep_all_keeps_everything(runtime):
    node = runtime.add_node(Node("n"))
    pub = node.create_publisher(Int32, "/x", 10)
    stream = node.subscribe(Int32, "/x", QoSProfile(history=HistoryPolicy.KEEP_ALL, depth=0))
    for i in range(200):
        pub.publish(Int32(data=i))
    got = [(await anext(stream)).data for _ in range(200)]
    assert got == list(range(200))
    assert stream.subscription.dropped == 0


async def test_subscribe_iterates_until_closed(runtime):
    node = runtime.add_node(Node("n"))
    pub = node.create_publisher(Int32, "/x", 10)
    seen = []

    async def reader():
        async with node.subscribe(Int32, "/x") as stream:
            async for msg in stream:
                seen.append(msg.data)
                if msg.data == 2:
                    break

    task = asyncio.create_task(reader())
    await settle(runtime)
    for i in range(3):
        pub.publish(Int32(data=i))
    await task
    assert seen == [0, 1, 2]
    assert runtime.graph.subscriptions_of("/x") == ()


async def test_transient_local_late_joiner_gets_last_depth_messages(runtime):
    node = runtime.add_node(Node("n"))
    pub = node.create_publisher(Int32, "/latched", TRANSIENT)
    for i in range(5):
        pub.publish(Int32(data=i))
    stream = node.subscribe(Int32, "/latched", TRANSIENT)
    got = [(await anext(stream)).data for _ in range(3)]
    assert got == [2, 3, 4]
    stream.close()


async def test_volatile_late_joiner_gets_nothing_old(runtime):
    node = runtime.add_node(Node("n"))
    pub = node.create_publisher(Int32, "/latched", TRANSIENT)
    pub.publish(Int32(data=1))
    stream = node.subscribe(Int32, "/latched", 10)
    await settle(runtime)
    assert stream.subscription.queued == 0
    pub.publish(Int32(data=2))
    assert (await anext(stream)).data == 2
    stream.close()


async def test_transient_local_published_before_the_node_joins_reaches_late_joiners(runtime):
    node = Node("early")
    pub = node.create_publisher(Int32, "/latched", TRANSIENT)
    pub.publish(Int32(data=42))
    runtime.add_node(node)
    probe = runtime.add_node(Node("probe"))
    msg = await wait_for_message(probe, Int32, "/latched", timeout_sec=10, qos=TRANSIENT)
    assert msg.data == 42


@pytest.mark.parametrize(
    ("pub_qos", "sub_qos", "policy"),
    [
        (QoSProfile(reliability=ReliabilityPolicy.BEST_EFFORT), QoSProfile(), "reliability"),
        (QoSProfile(), TRANSIENT, "durability"),
    ],
)
async def test_incompatible_pair_does_not_connect_and_warns(runtime, caplog, pub_qos, sub_qos, policy):
    talker = runtime.add_node(Node("talker"))
    listener = runtime.add_node(Node("listener"))
    pub = talker.create_publisher(Int32, "/x", pub_qos)
    with caplog.at_level(logging.WARNING, logger="aiorobot.runtime"):
        stream = listener.subscribe(Int32, "/x", sub_qos)
    warning = caplog.records[-1].getMessage()
    assert "incompatible QoS on /x" in warning
    assert "/talker" in warning and "/listener" in warning and policy in warning
    pub.publish(Int32(data=1))
    await settle(runtime)
    assert stream.subscription.received == 0
    assert pub.get_subscription_count() == 0
    [bad] = runtime.graph.incompatible_qos
    assert bad.topic == "/x" and bad.reason.startswith(policy)
    stream.close()
    assert runtime.graph.incompatible_qos == ()


async def test_strict_qos_raises_instead_of_warning():
    async with Runtime(strict_qos=True, handle_signals=False) as rt:
        node = rt.add_node(Node("n"))
        node.create_publisher(Int32, "/x", QoSProfile(reliability=ReliabilityPolicy.BEST_EFFORT))
        with pytest.raises(QoSIncompatibleError, match=r"reliability: publisher offers BEST_EFFORT"):
            node.create_subscription(Int32, "/x", print, 10)
        assert rt.graph.subscriptions_of("/x") == ()


async def test_strict_qos_rejects_a_whole_node_and_leaves_nothing_behind():
    class Bad(Node):
        def __init__(self):
            super().__init__("bad")
            self.create_publisher(String, "/ok", 10)
            self.create_subscription(Int32, "/x", print, 10)

    async with Runtime(strict_qos=True, handle_signals=False) as rt:
        good = rt.add_node(Node("good"))
        good.create_publisher(Int32, "/x", QoSProfile(reliability=ReliabilityPolicy.BEST_EFFORT))
        with pytest.raises(QoSIncompatibleError):
            rt.add_node(Bad())
        assert [n.name for n in rt.graph.nodes] == ["good"]
        assert rt.graph.topic("/ok") is None


async def test_mismatched_types_do_not_connect(runtime, caplog):
    node = runtime.add_node(Node("n"))
    pub = node.create_publisher(Int32, "/x", 10)
    with caplog.at_level(logging.WARNING, logger="aiorobot.runtime"):
        node.create_subscription(String, "/x", print, 10)
    # issue 18 item 6: said "incompatible QoS" before
    assert "type mismatch on /x: " in caplog.text and "incompatible QoS" not in caplog.text
    assert "(publisher sends std_msgs/msg/Int32, subscription expects std_msgs/msg/String)" in caplog.text
    assert pub.get_subscription_count() == 0
    [problem] = runtime.graph.incompatible_qos
    assert problem.kind == "type mismatch" and str(problem).startswith("type mismatch on /x: publisher of /n")


async def test_mismatched_types_under_strict_qos_say_type_mismatch():
    async with Runtime(strict_qos=True, handle_signals=False) as rt:
        node = rt.add_node(Node("n"))
        node.create_publisher(Int32, "/x", 10)
        with pytest.raises(QoSIncompatibleError, match="^type mismatch on /x: .*publisher sends std_msgs/msg/Int32"):
            node.create_subscription(String, "/x", print, 10)


async def test_publishing_the_wrong_type_raises(runtime):
    node = runtime.add_node(Node("n"))
    pub = node.create_publisher(Int32, "/x", 10)
    with pytest.raises(TypeError, match="expects std_msgs/msg/Int32, got String"):
        pub.publish(String())


async def test_callback_that_raises_is_logged_and_the_node_goes_on(runtime, caplog):
    got = []

    def cb(msg):
        if msg.data == 1:
            raise ValueError("boom")
        got.append(msg.data)

    node = runtime.add_node(Node("n"))
    pub = node.create_publisher(Int32, "/x", 10)
    node.create_subscription(Int32, "/x", cb, 10)
    with caplog.at_level(logging.ERROR):
        for i in range(3):
            pub.publish(Int32(data=i))
        await settle(runtime)
    assert got == [0, 2]
    [record] = [r for r in caplog.records if r.levelno == logging.ERROR]
    assert "subscription /x" in record.getMessage() and "/n" in record.getMessage()
    assert "ValueError: boom" in caplog.text


async def test_graph_lists_endpoints_with_types_and_qos(runtime):
    node = runtime.add_node(Node("n", namespace="r1"))
    node.create_publisher(Int32, "count", QoSProfile(depth=4))
    node.create_subscription(Int32, "count", print, 2)
    info = runtime.graph.topic("/r1/count")
    assert info.types == ("std_msgs/msg/Int32",)
    assert [(e.node, e.qos.depth) for e in info.publishers] == [("/r1/n", 4)]
    assert [(e.node, e.qos.depth) for e in info.subscriptions] == [("/r1/n", 2)]
    assert node.count_publishers("count") == 1 and node.count_subscribers("/r1/count") == 1
    assert '"/r1/n" -> "/r1/count"' in runtime.graph.to_dot()


async def test_removed_node_leaves_the_graph(runtime):
    node = runtime.add_node(Node("n"))
    node.create_publisher(Int32, "/x", 10)
    runtime.remove_node(node)
    assert runtime.graph.nodes == () and runtime.graph.topic("/x") is None


async def test_duplicate_node_names_are_rejected(runtime):
    runtime.add_node(Node("n"))
    with pytest.raises(ValueError, match="already in this runtime"):
        runtime.add_node(Node("n"))


async def test_add_nodes_under_strict_qos_is_all_or_nothing():
    class Talker(Node):
        def __init__(self):
            super().__init__("talker")
            self.create_publisher(Int32, "/x", QoSProfile(reliability=ReliabilityPolicy.BEST_EFFORT))

    class Listener(Node):
        def __init__(self):
            super().__init__("listener")
            self.create_subscription(Int32, "/x", print, 10)

    async with Runtime(strict_qos=True, handle_signals=False) as rt:
        [problem] = rt.check_qos([Talker(), Listener()])
        assert (problem.publisher_node, problem.subscription_node) == ("/talker", "/listener")
        with pytest.raises(QoSIncompatibleError, match="reliability"):
            rt.add_nodes([(Talker(), "main"), (Listener(), "priority")])
        assert rt.graph.nodes == () and rt.priority_loop is None
