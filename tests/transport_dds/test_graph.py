"""The graph over DDS: ros_discovery_info both ways, and the graph CLI listing a bare peer's node."""

from __future__ import annotations

import asyncio
import sys

from aiorobot import Node
from aiorobot.msgs import type_hash
from aiorobot.msgs.example_interfaces import AddTwoInts
from aiorobot.msgs.std_msgs import String

from ._helpers import BarePeer, dds_env, dds_runtime, wait_until

HASHES = {"req_hash": type_hash(AddTwoInts.Request), "rep_hash": type_hash(AddTwoInts.Response)}


async def _bare_node(peer: BarePeer) -> None:
    """The bare peer as ROS 2 node /bare/talker: a /chatter writer, an /add_two_ints server, announced."""
    await peer.cmd(op="writer", id="w", topic="rt/chatter", type="String", hash=type_hash(String))
    served = await peer.cmd(op="serve", srv="/add_two_ints", n=0, **HASHES)
    await peer.cmd(op="announce", node="talker", ns="/bare", writers=["w", "server_rep"], readers=["server_req"])
    assert served["reply_writer"]


async def test_aiorobot_names_a_bare_peers_node_and_its_endpoints(peer: BarePeer, domain_id: int) -> None:
    await _bare_node(peer)
    async with dds_runtime(domain_id) as rt:
        rt.add_node(Node("watcher"))
        await wait_until(lambda: rt.graph.node("/bare/talker") is not None)
        await wait_until(lambda: [p.node for p in rt.graph.publishers_of("/chatter")] == ["/bare/talker"])
        await wait_until(lambda: any(s.name == "/add_two_ints" and s.servers == ("/bare/talker",) for s in rt.graph.services))
        assert rt.transport.remote_nodes()[0].namespace == "/bare"
        await peer.cmd(op="leave")
        await wait_until(lambda: rt.graph.node("/bare/talker") is None and not rt.graph.publishers_of("/chatter"))
        assert not any(s.name == "/add_two_ints" for s in rt.graph.services)


async def test_a_bare_peer_reads_aiorobots_nodes_with_their_endpoint_gids(peer: BarePeer, domain_id: int) -> None:
    async with dds_runtime(domain_id) as rt:
        node = rt.add_node(Node("talker", namespace="/robot"))
        node.create_publisher(String, "/chatter", 10)
        node.create_subscription(String, "/heard", lambda m: None, 10)
        rt.add_node(Node("other"))
        out = await peer.cmd(op="nodes", expect="/robot/talker")
        writers = (await peer.cmd(op="endpoints", topic="rt/chatter"))["endpoints"]
        readers = (await peer.cmd(op="endpoints", topic="rt/heard"))["endpoints"]
    participants = out["participants"]
    assert list(participants) == [rt.transport.guid.hex()]
    nodes = {n["name"]: n for n in participants[rt.transport.guid.hex()]}
    assert {"/robot/talker", "/other"} <= set(nodes)
    assert writers[0]["guid"] in nodes["/robot/talker"]["writers"]
    assert readers[0]["guid"] in nodes["/robot/talker"]["readers"]
    assert writers[0]["guid"] not in nodes["/other"]["writers"]


async def _cli(domain_id: int, *argv: str) -> str:
    proc = await asyncio.create_subprocess_exec(
        sys.executable, "-m", "aiorobot.cli", *argv, "--transport", "dds", stdout=asyncio.subprocess.PIPE,
        stderr=asyncio.subprocess.PIPE, env=dds_env(domain_id),
    )
    out, err = await proc.communicate()
    assert proc.returncode == 0, err.decode()
    return out.decode()


async def test_the_graph_cli_lists_a_bare_peers_node_topic_and_service(peer: BarePeer, domain_id: int) -> None:
    await _bare_node(peer)
    nodes, info, services = await asyncio.gather(  # (topic list reads the same graph as topic info)
        _cli(domain_id, "node", "list"), _cli(domain_id, "topic", "info", "-v", "/chatter"), _cli(domain_id, "service", "list"),
    )
    assert "/bare/talker" in nodes.split()
    assert "Node name: talker\nNode namespace: /bare\n" in info and "Type: std_msgs/msg/String" in info
    assert "Endpoint type: PUBLISHER" in info and "Reliability: RELIABLE" in info and "KEEP_LAST (10)" in info
    assert "/add_two_ints" in services.split()


async def test_endpoints_that_leave_leave_their_nodes_gid_lists(peer: BarePeer, domain_id: int) -> None:
    async with dds_runtime(domain_id) as rt:
        first = rt.add_node(Node("first"))
        second = rt.add_node(Node("second"))
        kept = first.create_publisher(String, "/chatter", 10)
        gone = second.create_publisher(String, "/chatter", 10)  # the same DDS writer serves both
        writer = (await peer.cmd(op="endpoints", topic="rt/chatter"))["endpoints"][0]["guid"]
        nodes = await peer.cmd(op="nodes", expect="/second")

        def writers(info: dict, name: str) -> list[str]:
            return [w for ns in info["participants"].values() for n in ns if n["name"] == name for w in n["writers"]]

        assert writer in writers(nodes, "/first") and writer in writers(nodes, "/second")
        second.destroy_publisher(gone)
        async with asyncio.timeout(20):  # each participant state replaces the one before: read until the new one
            while True:
                later = await peer.cmd(op="nodes", expect="/second", timeout=0.5)
                if writer in writers(later, "/first") and writer not in writers(later, "/second"):
                    break
        assert kept.get_subscription_count() == 0
