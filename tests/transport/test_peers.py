"""Peers that die, restart, or live in another domain."""

from __future__ import annotations

from aiorobot import Node, PublisherEventCallbacks, SubscriptionEventCallbacks
from aiorobot.msgs.std_msgs import String

from ._helpers import peer_runtime, spawn, wait_until

TALKER = """
from aiorobot.msgs.std_msgs import String
async def main(rt):
    node = rt.add_node(Node("doomed"))
    pub = node.create_publisher(String, "/chatter", 10)
    say("ready")
    reader = await stdin_lines()
    while line := (await reader.readline()).decode().strip():
        pub.publish(String(data=line))
        say("sent", line)
"""


async def test_a_killed_peer_leaves_the_graph_and_is_rediscovered_when_it_restarts(router_port: int) -> None:
    async with peer_runtime(router_port) as rt:
        node = rt.add_node(Node("survivor"))
        got: list[str] = []
        node.create_subscription(String, "/chatter", lambda m: got.append(m.data), 10)
        for round_ in range(10):
            child = await spawn(TALKER, router_port)
            try:
                await child.expect("ready")
                await wait_until(lambda: rt.graph.node("/doomed") is not None and node.count_publishers("/chatter") == 1)
                word = f"round{round_}"
                while word not in got:
                    child.send(word)
                    await child.expect("sent")
            finally:
                await child.stop()  # SIGKILL: no goodbye from the child
            await wait_until(lambda: rt.graph.node("/doomed") is None and node.count_publishers("/chatter") == 0)
        assert rt.graph.node("/survivor") is not None  # this side kept running throughout


async def test_domains_do_not_see_each_other(router_port: int) -> None:
    child = await spawn(TALKER, router_port, domain_id=7)
    try:
        await child.expect("ready")
        async with peer_runtime(router_port, domain_id=3) as other, peer_runtime(router_port, domain_id=7) as same:
            seen_other: list[str] = []
            seen_same: list[str] = []
            other.add_node(Node("o")).create_subscription(String, "/chatter", lambda m: seen_other.append(m.data), 10)
            same.add_node(Node("s")).create_subscription(String, "/chatter", lambda m: seen_same.append(m.data), 10)
            await wait_until(lambda: same.graph.node("/doomed") is not None)
            while not seen_same:
                child.send("hello")
                await child.expect("sent")
            assert other.graph.node("/doomed") is None and other.graph.node("/s") is None
            assert seen_other == []
    finally:
        await child.stop()


async def test_remote_endpoints_match_local_ones_and_unmatch_when_their_peer_leaves(router_port: int) -> None:
    async with peer_runtime(router_port) as rt:
        node = rt.add_node(Node("detect"))
        pub_got: list[tuple[int, int]] = []
        sub_got: list[tuple[int, int]] = []
        node.create_publisher(String, "/matched_a", 10, event_callbacks=PublisherEventCallbacks(
            matched=lambda info: pub_got.append((info.total_count, info.current_count))))
        node.create_subscription(String, "/matched_b", lambda m: None, 10, event_callbacks=SubscriptionEventCallbacks(
            matched=lambda info: sub_got.append((info.total_count, info.current_count))))
        async with peer_runtime(router_port) as other:
            remote = other.add_node(Node("remote"))
            remote.create_subscription(String, "/matched_a", lambda m: None, 10)
            remote.create_publisher(String, "/matched_b", 10)
            await wait_until(lambda: pub_got[-1:] == [(1, 1)] and sub_got[-1:] == [(1, 1)])
        await wait_until(lambda: pub_got[-1] == (1, 0) and sub_got[-1] == (1, 0))  # the peer left
        assert pub_got == [(1, 1), (1, 0)] and sub_got == [(1, 1), (1, 0)]
