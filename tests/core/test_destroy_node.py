"""``Node.destroy_node``: rclpy's way to take a node out of the graph."""

from __future__ import annotations

import asyncio

from aiorobot import Node, Runtime
from aiorobot.msgs.std_msgs import String


async def test_destroy_node_removes_it_from_the_runtime_and_its_topics():
    async with Runtime(handle_signals=False) as rt:
        talker = rt.add_node(Node("talker"))
        pub = talker.create_publisher(String, "/chatter", 10)
        got: list[str] = []
        listener = rt.add_node(Node("listener"))
        listener.create_subscription(String, "/chatter", lambda m: got.append(m.data), 10)
        assert pub.get_subscription_count() == 1
        listener.destroy_node()
        assert listener not in rt.nodes
        assert pub.get_subscription_count() == 0
        assert listener.subscriptions == ()
        pub.publish(String(data="after"))
        await asyncio.sleep(0.05)
        assert got == []
        listener.destroy_node()  # idempotent
        assert "/listener" not in {n.fully_qualified_name for n in rt.graph.nodes}


async def test_destroy_node_of_a_node_never_added_destroys_its_entities():
    node = Node("alone")
    pub = node.create_publisher(String, "/x", 10)
    node.create_timer(1.0, lambda: None)
    node.destroy_node()
    assert pub.destroyed and node.publishers == () and node.timers == ()
    node.destroy_node()
