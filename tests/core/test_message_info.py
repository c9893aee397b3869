"""A subscription callback taking two arguments gets rclpy's MessageInfo; raw=True gets CDR bytes."""

import pytest

from aiorobot import DurabilityPolicy, Node, QoSProfile
from aiorobot.msgs import serialize
from aiorobot.msgs.std_msgs import Int32
from aiorobot.testing import settle

KEYS = {"source_timestamp", "received_timestamp", "publication_sequence_number", "reception_sequence_number"}


async def test_two_argument_callback_gets_message_info(runtime):
    # rclpy subscription.py Subscription.callback setter and _rclpy Subscription.take_message's dict
    node = runtime.add_node(Node("info"))
    got = []
    node.create_subscription(Int32, "/n", lambda msg, info: got.append((msg.data, info)), 10)
    pub = node.create_publisher(Int32, "/n", 10)
    for k in range(3):
        pub.publish(Int32(data=k))
    await settle(runtime)
    assert [data for data, _ in got] == [0, 1, 2]
    for k, (_, info) in enumerate(got, start=1):
        assert type(info) is dict and set(info) == KEYS
        assert info["publication_sequence_number"] == k
        assert info["reception_sequence_number"] == k
        assert 0 < info["source_timestamp"] <= info["received_timestamp"]


async def test_a_publish_method_kept_before_the_info_subscription_came_still_gives_it_info(runtime):
    # a relay passes pub.publish as a callback before its subscribers exist: the method it kept
    # must serve whoever matches later (here a callback that takes MessageInfo)
    node = runtime.add_node(Node("relay"))
    pub = node.create_publisher(Int32, "/out", 10)
    node.create_subscription(Int32, "/in", pub.publish, 10)
    relayed, seen = [], []
    node.create_subscription(Int32, "/out", lambda msg, info: relayed.append(info), 10)
    node.create_subscription(Int32, "/out", seen.append, 10)
    source = node.create_publisher(Int32, "/in", 10)
    for k in range(2):
        source.publish(Int32(data=k))
    await settle(runtime)
    assert [m.data for m in seen] == [0, 1]
    assert [info["publication_sequence_number"] for info in relayed] == [1, 2]


async def test_message_info_on_another_loop_and_from_a_late_joiner_history(runtime):
    node = runtime.add_node(Node("pub"))
    qos = QoSProfile(depth=5, durability=DurabilityPolicy.TRANSIENT_LOCAL)
    pub = node.create_publisher(Int32, "/latched", qos)
    pub.publish(Int32(data=7))  # published before anyone wanted info: no publisher data
    got = []

    class Listener(Node):
        def __init__(self):
            super().__init__("listener")
            self.create_subscription(Int32, "/latched", self.on_msg, qos)

        def on_msg(self, msg, message_info):
            got.append((msg.data, message_info))

    runtime.add_node(Listener(), executor="priority")
    await settle(runtime)
    pub.publish(Int32(data=8))
    for _ in range(200):
        await settle(runtime)
        if len(got) == 2:
            break
    assert [d for d, _ in got] == [7, 8]
    first, second = got[0][1], got[1][1]
    assert first["publication_sequence_number"] is None and first["reception_sequence_number"] == 1
    assert second["publication_sequence_number"] == 2 and second["reception_sequence_number"] == 2


async def test_one_argument_callbacks_get_the_message_only(runtime):
    node = runtime.add_node(Node("plain"))
    got = []

    def with_default(msg, extra="unused"):
        got.append((msg.data, extra))

    node.create_subscription(Int32, "/n", with_default, 10)
    node.create_publisher(Int32, "/n", 10).publish(Int32(data=1))
    await settle(runtime)
    assert got == [(1, "unused")]


async def test_callback_that_takes_neither_one_nor_two_arguments_is_refused(runtime):
    node = runtime.add_node(Node("bad"))
    with pytest.raises(RuntimeError, match="callable with one argument"):
        node.create_subscription(Int32, "/n", lambda: None, 10)
    with pytest.raises(RuntimeError, match="or two"):
        node.create_subscription(Int32, "/n", lambda a, b, c: None, 10)


async def test_raw_subscription_gets_cdr_bytes(runtime):
    node = runtime.add_node(Node("raw"))
    got = []
    node.create_subscription(Int32, "/n", got.append, 10, raw=True)
    node.create_publisher(Int32, "/n", 10).publish(Int32(data=-5))
    await settle(runtime)
    assert got == [serialize(Int32(data=-5))]
