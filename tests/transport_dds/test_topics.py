"""Topics between aiorobot on DDS and a bare cyclonedds-python peer: data both ways, late joiners,
domains, USER_DATA type hashes, malformed samples and mismatched types."""

from __future__ import annotations

import asyncio
import json
import logging
from typing import Any

import numpy as np
import pytest

from aiorobot import Node, QoSProfile
from aiorobot.msgs import serialize, type_hash
from aiorobot.msgs.geometry_msgs import Twist, Vector3
from aiorobot.msgs.sensor_msgs import Image
from aiorobot.msgs.std_msgs import String
from aiorobot import DurabilityPolicy

from ._helpers import BarePeer, dds_runtime, wait_until

H_STRING = type_hash(String)
TL = QoSProfile(durability=DurabilityPolicy.TRANSIENT_LOCAL, depth=5)


async def test_string_twist_image_from_a_bare_writer_reach_aiorobot_subscriptions(peer: BarePeer, domain_id: int) -> None:
    async with dds_runtime(domain_id) as rt:
        node = rt.add_node(Node("listener"))
        got: dict[str, list] = {"s": [], "t": [], "i": []}
        node.create_subscription(String, "/chatter", lambda m: got["s"].append(m), 10)
        node.create_subscription(Twist, "/cmd_vel", lambda m: got["t"].append(m), 10)
        node.create_subscription(Image, "/image", lambda m: got["i"].append(m), 10)
        for wid, topic, kind in (("s", "rt/chatter", "String"), ("t", "rt/cmd_vel", "Twist"), ("i", "rt/image", "Image")):
            await peer.cmd(op="writer", id=wid, topic=topic, type=kind, hash=type_hash({"String": String, "Twist": Twist, "Image": Image}[kind]))
            assert (await peer.cmd(op="matched", id=wid))["matched"]
        await peer.cmd(op="write", id="s", type="String", value={"data": "héllo"})
        await peer.cmd(op="write", id="t", type="Twist", value={"linear": {"x": 0.5, "y": 0.0, "z": 0.0}, "angular": {"x": 0.0, "y": 0.0, "z": -1.25}})
        pixels = list(range(256)) * 3 * 4  # 4x64 rgb8
        await peer.cmd(op="write", id="i", type="Image", value={
            "header": {"stamp": {"sec": 7, "nanosec": 9}, "frame_id": "cam"}, "height": 4, "width": 64,
            "encoding": "rgb8", "is_bigendian": 0, "step": 192, "data": pixels})
        await wait_until(lambda: all(got.values()))
        assert got["s"][0].data == "héllo"
        assert (got["t"][0].linear.x, got["t"][0].angular.z) == (0.5, -1.25)
        img = got["i"][0]
        assert (img.header.stamp.sec, img.header.frame_id, img.height, img.width, img.encoding) == (7, "cam", 4, 64, "rgb8")
        assert np.asarray(img.data).tolist() == pixels


async def test_aiorobot_publishers_reach_a_bare_reader_with_byte_identical_cdr(peer: BarePeer, domain_id: int) -> None:
    async with dds_runtime(domain_id) as rt:
        node = rt.add_node(Node("talker"))
        pubs = {
            "s": (node.create_publisher(String, "/chatter", 10), String(data="hi")),
            "t": (node.create_publisher(Twist, "/cmd_vel", 10), Twist(linear=Vector3(x=1.5), angular=Vector3(z=0.25))),
            "i": (node.create_publisher(Image, "/image", 10),
                  Image(height=2, width=3, encoding="mono8", step=3, data=np.arange(6, dtype=np.uint8))),
        }
        for rid, topic, kind in (("s", "rt/chatter", "String"), ("t", "rt/cmd_vel", "Twist"), ("i", "rt/image", "Image")):
            await peer.cmd(op="reader", id=rid, topic=topic, type=kind)
        await wait_until(lambda: all(p.get_subscription_count() == 1 for p, _ in pubs.values()))
        s, t, i = [await _published_until_taken(peer, rid, *pubs[rid]) for rid in ("s", "t", "i")]
        await peer.cmd(op="reader", id="raw", topic="rt/chatter", type="String")
        await wait_until(lambda: pubs["s"][0].get_subscription_count() == 2)
        take = asyncio.ensure_future(peer.cmd(op="take_raw", id="raw", timeout=20))
        while not take.done():
            pubs["s"][0].publish(String(data="hi"))
            await asyncio.wait([take], timeout=0.05)
        raw = take.result()["raw"]
    assert s[0] == {"data": "hi"}
    # the bytes on the wire are ROS 2's CDR of the message (INTEROP §8.3), padded to 4 as Cyclone's writers do
    assert t[0]["linear"]["x"] == 1.5 and t[0]["angular"]["z"] == 0.25
    assert i[0]["data"] == [0, 1, 2, 3, 4, 5] and i[0]["encoding"] == "mono8"
    assert raw[0] == "00010000" "03000000" "686900" "00"
    assert raw[0].startswith(serialize(String(data="hi")).hex())


async def _published_until_taken(peer: BarePeer, reader: str, pub: Any, msg: Any) -> list[dict[str, Any]]:
    """Publish ``msg`` until the bare reader has it: the remote reader is in the graph once discovered,
    which can come a moment before Cyclone has matched it with this side's writer."""
    take = asyncio.ensure_future(peer.cmd(op="take", id=reader, timeout=20))
    while not take.done():
        pub.publish(msg)
        await asyncio.wait([take], timeout=0.05)
    samples: list[dict[str, Any]] = take.result()["samples"]
    return samples


async def test_a_late_joiner_gets_a_transient_local_history_both_ways(peer: BarePeer, domain_id: int) -> None:
    await peer.cmd(op="writer", id="w", topic="rt/latched", type="String", tl=True, depth=5, hash=H_STRING)
    for i in range(3):
        await peer.cmd(op="write", id="w", type="String", value={"data": f"old{i}"})
    async with dds_runtime(domain_id) as rt:
        node = rt.add_node(Node("late"))
        got: list[str] = []
        node.create_subscription(String, "/latched", lambda m: got.append(m.data), TL)
        await wait_until(lambda: len(got) == 3)
        assert got == ["old0", "old1", "old2"]
        pub = node.create_publisher(String, "/mine", TL)
        for i in range(3):
            pub.publish(String(data=f"kept{i}"))
        await peer.cmd(op="reader", id="r", topic="rt/mine", type="String", tl=True, depth=5)
        samples = (await peer.cmd(op="take", id="r", n=3))["samples"]
    assert [s["data"] for s in samples] == ["kept0", "kept1", "kept2"]


async def test_every_endpoint_carries_the_rihs01_type_hash_in_user_data(peer: BarePeer, domain_id: int) -> None:
    async with dds_runtime(domain_id) as rt:
        node = rt.add_node(Node("hashes"))
        node.create_publisher(Twist, "/cmd_vel", QoSProfile(depth=3))
        node.create_subscription(Image, "/image", lambda m: None, 10)
        pubs = (await peer.cmd(op="endpoints", topic="rt/cmd_vel"))["endpoints"]
        subs = (await peer.cmd(op="endpoints", topic="rt/image"))["endpoints"]
        info = (await peer.cmd(op="endpoints", topic="ros_discovery_info"))["endpoints"]
    assert [(e["kind"], e["type"], e["userdata"]) for e in pubs] == [
        ("writer", "geometry_msgs::msg::dds_::Twist_", f"typehash={type_hash(Twist)};")]
    assert [(e["kind"], e["type"], e["userdata"]) for e in subs] == [
        ("reader", "sensor_msgs::msg::dds_::Image_", f"typehash={type_hash(Image)};")]
    assert {e["userdata"] for e in info} == {"typehash=RIHS01_91a0593bacdcc50ea9bdcf849a938b128412cc1ea821245c663bcd26f83c295e;"}


async def test_domains_are_isolated(domain_id: int) -> None:
    other = domain_id + 100 if domain_id < 2 else domain_id - 1  # another worker's ids are not used at once here
    async with await BarePeer.start(other) as stranger:
        await stranger.cmd(op="writer", id="w", topic="rt/chatter", type="String", hash=H_STRING)
        async with dds_runtime(domain_id) as rt:
            node = rt.add_node(Node("alone"))
            got: list[str] = []
            node.create_subscription(String, "/chatter", lambda m: got.append(m.data), 10)
            assert not (await stranger.cmd(op="matched", id="w", timeout=1.0))["matched"]
            await stranger.cmd(op="write", id="w", type="String", value={"data": "other domain"})
            await rt.settle()
            assert got == [] and node.count_publishers("/chatter") == 0


async def test_a_malformed_sample_is_dropped_and_counted(peer: BarePeer, domain_id: int, caplog: pytest.LogCaptureFixture) -> None:
    async with dds_runtime(domain_id) as rt:
        node = rt.add_node(Node("robust"))
        got: list[str] = []
        node.create_subscription(String, "/chatter", lambda m: got.append(m.data), 10)
        await peer.cmd(op="writer", id="w", topic="rt/chatter", type="String", hash=H_STRING)
        assert (await peer.cmd(op="matched", id="w"))["matched"]
        with caplog.at_level(logging.WARNING, "aiorobot.transport"):
            # a string that is not UTF-8: Cyclone's own check lets it through, aiorobot's decoder must not
            await peer.cmd(op="write_raw", id="w", hex="00010000" "03000000" "ff fe 00 00".replace(" ", ""))
            await peer.cmd(op="write", id="w", type="String", value={"data": "after"})
            await wait_until(lambda: got == ["after"])
        transport = rt.transport
        assert transport.statistics().drop_reasons == {"cdr": 1}
        assert "malformed CDR" in caplog.text


async def test_a_type_hash_mismatch_is_reported_and_not_delivered(peer: BarePeer, domain_id: int, caplog: pytest.LogCaptureFixture) -> None:
    async with dds_runtime(domain_id) as rt:
        node = rt.add_node(Node("strict"))
        got: list[str] = []
        node.create_subscription(String, "/chatter", lambda m: got.append(m.data), 10)
        with caplog.at_level(logging.WARNING, "aiorobot.transport"):
            await peer.cmd(op="writer", id="w", topic="rt/chatter", type="String", hash="RIHS01_" + "ab" * 32)
            await wait_until(lambda: "type mismatch on /chatter" in caplog.text)
            assert (await peer.cmd(op="matched", id="w"))["matched"]  # DDS matches on the name: aiorobot refuses
            await peer.cmd(op="write", id="w", type="String", value={"data": "wrong definition"})
            await wait_until(lambda: rt.transport.statistics().drop_reasons.get("type_hash", 0) >= 2)
        assert got == [] and node.count_publishers("/chatter") == 0
        assert "RIHS01_abab" in caplog.text and H_STRING in caplog.text


async def test_a_remote_type_name_or_qos_mismatch_is_reported_as_on_the_bus(peer: BarePeer, domain_id: int) -> None:
    from aiorobot.msgs.std_msgs import Int32

    async with dds_runtime(domain_id) as rt:
        node = rt.add_node(Node("picky"))
        node.create_subscription(String, "/chatter", lambda m: None, 10)
        node.create_subscription(String, "/reliable_only", lambda m: None, 10)
        await peer.cmd(op="writer", id="i", topic="rt/chatter", type="Int32", hash=type_hash(Int32))
        await peer.cmd(op="writer", id="b", topic="rt/reliable_only", type="String", hash=H_STRING, best_effort=True)
        await wait_until(lambda: len(rt.graph.incompatible_qos) == 2)
        found = {(i.topic, i.kind, i.subscription_node) for i in rt.graph.incompatible_qos}
    assert found == {("/chatter", "type mismatch", "/picky"), ("/reliable_only", "incompatible QoS", "/picky")}


async def test_a_priority_loop_subscription_receives_while_the_main_loop_is_blocked(peer: BarePeer, domain_id: int) -> None:
    """A DDS topic whose subscription runs on the priority loop is handed to that loop, not through
    the main loop: a blocked main-loop callback does not hold back a remote /cmd_vel."""
    import threading

    async with dds_runtime(domain_id) as rt:
        control = rt.add_node(Node("controller"), executor="priority")
        arrived = threading.Event()
        got: list[float] = []

        def on_cmd(msg: Twist) -> None:
            got.append(msg.linear.x)
            arrived.set()

        control.create_subscription(Twist, "/cmd_vel", on_cmd, 10)
        await peer.cmd(op="writer", id="t", topic="rt/cmd_vel", type="Twist", hash=type_hash(Twist))
        assert (await peer.cmd(op="matched", id="t"))["matched"]
        write = {"op": "write", "id": "t", "type": "Twist",
                 "value": {"linear": {"x": 0.75, "y": 0.0, "z": 0.0}, "angular": {"x": 0.0, "y": 0.0, "z": 0.0}}}
        assert peer.proc.stdin is not None
        peer.proc.stdin.write((json.dumps(write) + "\n").encode())
        await peer.proc.stdin.drain()
        # the main loop blocks (a synchronous wait) before the peer writes, until the priority loop has it
        assert arrived.wait(timeout=20), "the priority loop got nothing while the main loop was blocked"
        assert got == [0.75]
        await peer._line(peer.proc)  # the peer's answer to the write


async def test_a_received_message_is_not_written_back_by_a_participant_that_publishes_its_topic_too(domain_id: int) -> None:
    """Two participants that both publish and subscribe one topic (as /tf is): what one receives
    goes to its subscriptions, not out again over DDS, so nothing comes back."""
    qos = QoSProfile(depth=50)
    async with dds_runtime(domain_id) as near, dds_runtime(domain_id) as far:
        here: list[int] = []
        there: list[int] = []
        talker = near.add_node(Node("talker"))
        pub = talker.create_publisher(Twist, "/chatter", qos)
        talker.create_subscription(Twist, "/chatter", lambda m: here.append(int(m.linear.x)), qos)
        other = far.add_node(Node("other"))
        other.create_publisher(Twist, "/chatter", qos)  # far writes /chatter too
        other.create_subscription(Twist, "/chatter", lambda m: there.append(int(m.linear.x)), qos)
        await wait_until(lambda: talker.count_subscribers("/chatter") == 2 and other.count_publishers("/chatter") == 2)
        n = 0
        while not there:  # until the reader has matched
            n += 1
            pub.publish(Twist(linear=Vector3(x=-float(n))))
            try:
                await wait_until(lambda: bool(there), 0.2)
            except TimeoutError:
                pass
        for i in range(20):
            pub.publish(Twist(linear=Vector3(x=float(i))))
        await wait_until(lambda: there[-1] == 19)
        await near.settle()
        assert [x for x in there if x >= 0] == list(range(20))
        assert far.transport.statistics().sent == 0
        assert len(here) == n + 20  # its own, delivered in process, and none of them twice
        assert near.transport.statistics().received == 0
