"""rmw_zenoh's wire format, spoken by a bare zenoh session written from INTEROP facts alone.

Nothing here uses aiorobot's encoder: keys and tokens are written out by hand, the
attachment with ``struct``, CDR with rosbags.
"""

from __future__ import annotations

import asyncio
import random
import struct
import time
from typing import Any

import pytest
import xxhash
import zenoh
from rosbags.typesys import Stores, get_typestore

from aiorobot import Node, QoSProfile
from aiorobot.msgs.example_interfaces import AddTwoInts
from aiorobot.msgs.std_msgs import String
from aiorobot.transport._wire import parse_qos, parse_token, qos_chunk

from ._helpers import peer_runtime, wait_until

STRING_HASH = "RIHS01_df668c740482bbd48fb39d76a70dfd4bd59db1288021743503259e948f6b1a18"
ADD_HASH = "RIHS01_e118de6bf5eeb66a2491b5bda11202e7b68f198d6f67922cf30364858239c81a"
TS = get_typestore(Stores.ROS2_JAZZY)  # rosbags bundles no service types: those are written with struct
CDR_LE = b"\x00\x01\x00\x00"


def bare_session(port: int) -> Any:
    cfg = zenoh.Config()
    cfg.insert_json5("mode", '"peer"')
    cfg.insert_json5("connect/endpoints", f'["tcp/127.0.0.1:{port}"]')
    cfg.insert_json5("listen/endpoints", '["tcp/127.0.0.1:0"]')
    cfg.insert_json5("scouting/multicast/enabled", "false")
    return zenoh.open(cfg)


def rmw_gid(token: str) -> bytes:
    v = xxhash.xxh3_128(token.encode()).intdigest()
    return struct.pack("<QQ", v & (2**64 - 1), v >> 64)


def cdr_string(text: str) -> bytes:
    msg = TS.types["std_msgs/msg/String"](data=text)
    return bytes(TS.serialize_cdr(msg, "std_msgs/msg/String", little_endian=True))


def test_qos_chunk_round_trips_and_reads_rmw_defaults() -> None:
    qos = QoSProfile(depth=7)
    assert qos_chunk(qos) == "1:2:1,7:,:,:,,"
    assert parse_qos(qos_chunk(qos)) == qos
    assert parse_qos("::,7:,:,:,,") == qos  # rmw_zenoh leaves defaults empty
    assert parse_qos("::,:,:,:,,").depth == 42


def test_attachment_matches_zenoh_ext_serialization() -> None:
    from zenoh.ext import Int64, z_serialize

    from aiorobot.transport._wire import pack_attachment, unpack_attachment

    gid = bytes(range(16))
    ours = pack_attachment(5, 123456789, gid)
    assert ours == z_serialize((Int64(5), Int64(123456789), gid)).to_bytes()
    assert unpack_attachment(ours).gid == gid


async def test_bare_session_talks_to_aiorobot_both_ways(router_port: int) -> None:
    s = bare_session(router_port)
    zid = str(s.zid())
    try:
        lv = s.liveliness()
        node_tok = f"@ros2_lv/0/{zid}/0/0/NN/%/%/bare"
        pub_tok = f"@ros2_lv/0/{zid}/0/10/MP/%/%/bare/%chatter/std_msgs::msg::dds_::String_/{STRING_HASH}/::,7:,:,:,,"
        tokens = [lv.declare_token(node_tok), lv.declare_token(pub_tok)]
        seen_tokens: list[str] = []
        watcher = lv.declare_subscriber("@ros2_lv/0/**", lambda sample: seen_tokens.append(str(sample.key_expr)), history=True)
        received: list[tuple[bytes, bytes, str]] = []
        bare_sub = s.declare_subscriber(
            f"0/echo/std_msgs::msg::dds_::String_/{STRING_HASH}",
            lambda sample: received.append((sample.payload.to_bytes(), sample.attachment.to_bytes(), str(sample.key_expr))),
        )

        def serve(query: Any) -> None:
            a, b = struct.unpack("<4xqq", query.payload.to_bytes())  # CDR_LE header, int64 a, int64 b
            query.reply(query.key_expr, CDR_LE + struct.pack("<q", a * b), attachment=query.attachment)

        ss_tok = f"@ros2_lv/0/{zid}/0/11/SS/%/%/bare/%mul/example_interfaces::srv::dds_::AddTwoInts_/{ADD_HASH}/::,10:,:,:,,"
        tokens.append(lv.declare_token(ss_tok))
        queryable = s.declare_queryable(f"0/mul/example_interfaces::srv::dds_::AddTwoInts_/{ADD_HASH}", serve, complete=True)

        async with peer_runtime(router_port) as rt:
            node = rt.add_node(Node("aio"))
            got: list[str] = []
            node.create_subscription(String, "/chatter", lambda m: got.append(m.data), 10)
            echo = node.create_publisher(String, "/echo", 10)
            node.create_service(AddTwoInts, "/add", lambda r: AddTwoInts.Response(sum=r.a + r.b))
            await wait_until(lambda: rt.graph.node("/bare") is not None and node.count_publishers("/chatter") == 1)
            assert rt.graph.publishers_of("/chatter")[0].qos.depth == 7

            # bare -> aiorobot: topic
            gid = rmw_gid(pub_tok)
            seq = 0
            while "from bare" not in got:
                seq += 1
                s.put(f"0/chatter/std_msgs::msg::dds_::String_/{STRING_HASH}", cdr_string("from bare"),
                      attachment=struct.pack("<qqB", seq, time.time_ns(), 16) + gid)
                await rt_settle()
            # aiorobot -> bare: topic, with its token, GID and attachment
            await wait_until(lambda: any("/MP/" in t and "/%echo/" in t for t in seen_tokens))
            mp = [t for t in seen_tokens if "/MP/" in t and "/%echo/" in t]
            assert len(mp) == 1 and parse_token(mp[0]).node == "aio"
            while not received:
                echo.publish(String(data="to bare"))
                await rt_settle()
            payload, attachment, key = received[0]
            assert TS.deserialize_cdr(payload, "std_msgs/msg/String").data == "to bare"
            assert payload[:4] == b"\x00\x01\x00\x00" and len(attachment) == 33
            seq_, ts_, n = struct.unpack_from("<qqB", attachment)
            assert seq_ >= 1 and abs(ts_ - time.time_ns()) < 60e9 and n == 16
            assert attachment[17:] == rmw_gid(mp[0])

            # aiorobot -> bare: service
            client = node.create_client(AddTwoInts, "/mul")
            assert await client.wait_for_service(timeout_sec=10)
            assert (await client.call(AddTwoInts.Request(a=6, b=7), timeout_sec=10)).sum == 42
            # bare -> aiorobot: service (ALL_COMPLETE, consolidation NONE, attachment with the client GID)
            await wait_until(lambda: any("/SS/" in t and "/%add/" in t for t in seen_tokens))
            client_gid = bytes(range(16))
            replies = await asyncio.to_thread(lambda: list(s.get(
                f"0/add/example_interfaces::srv::dds_::AddTwoInts_/{ADD_HASH}",
                payload=CDR_LE + struct.pack("<qq", 40, 2),
                attachment=struct.pack("<qqB", 9, time.time_ns(), 16) + client_gid,
                target=zenoh.QueryTarget.ALL_COMPLETE, consolidation=zenoh.ConsolidationMode.NONE, timeout=10,
            )))
            ok = [r.ok for r in replies if r.ok is not None]
            assert len(ok) == 1
            assert struct.unpack("<4xq", ok[0].payload.to_bytes()) == (42,)
            reply_att = ok[0].attachment.to_bytes()
            assert struct.unpack_from("<q", reply_att)[0] == 9 and reply_att[17:] == client_gid
        queryable.undeclare()
        watcher.undeclare()
        bare_sub.undeclare()
        for t in tokens:
            t.undeclare()
    finally:
        s.close()


async def rt_settle() -> None:
    await asyncio.sleep(0.01)  # let zenoh's threads hand the sample over; loops poll the outcome


async def test_malformed_input_from_the_network_is_dropped_counted_and_never_reaches_user_code(
    router_port: int, caplog: pytest.LogCaptureFixture
) -> None:
    rng = random.Random(14)
    s = bare_session(router_port)
    try:
        async with peer_runtime(router_port) as rt:
            node = rt.add_node(Node("victim"))
            got: list[str] = []
            node.create_subscription(String, "/chatter", lambda m: got.append(m.data), 100)
            key = f"0/chatter/std_msgs::msg::dds_::String_/{STRING_HASH}"
            good_att = struct.pack("<qqB", 1, time.time_ns(), 16) + bytes(16)
            # wait until the subscriber is reachable: a valid sample arrives
            while "probe" not in got:
                s.put(key, cdr_string("probe"), attachment=good_att)
                await rt_settle()
            before = rt.transport.statistics().dropped  # type: ignore[attr-defined]
            bad = 0
            s.put(key, cdr_string("no attachment"))
            s.put(key, cdr_string("short attachment"), attachment=b"\x01\x02")
            s.put(key, cdr_string("long attachment"), attachment=good_att + b"x")
            s.put(f"0/chatter/std_msgs::msg::dds_::String_/RIHS01_{'0' * 64}", cdr_string("wrong hash"), attachment=good_att)
            bad += 4
            for _ in range(40):
                junk = bytes(rng.randrange(256) for _ in range(rng.randrange(0, 40)))
                s.put(key, junk, attachment=good_att)
                bad += 1
            s.liveliness().declare_token("@ros2_lv/0/not/a/valid/token")
            s.put(key, cdr_string("after the storm"), attachment=good_att)
            await wait_until(lambda: "after the storm" in got)
            stats = rt.transport.statistics()  # type: ignore[attr-defined]
            # random bytes can happen to be valid CDR for a String: those arrive as ordinary messages
            valid_junk = [g for g in got if g not in ("probe", "after the storm")]
            sample_drops = stats.dropped - stats.drop_reasons.get("token", 0) - before
            assert sample_drops + len(valid_junk) == bad
            assert {"wire", "cdr"} <= set(stats.drop_reasons)
            assert "no attachment" not in got and "wrong hash" not in got and "short attachment" not in got
            assert rt.graph.node("/victim") is not None
            assert any("dropped a sample" in r.message for r in caplog.records)
    finally:
        s.close()


async def test_gaps_in_a_publisher_s_sequence_numbers_are_reported_as_lost_messages(
    router_port: int, caplog: pytest.LogCaptureFixture
) -> None:
    """As rmw_zenoh counts them: per publisher GID, a sequence number more than one past the last
    one seen means the messages between never arrived. They are counted on the subscription's
    ``message_lost`` event and said in one line; a lower number (a copy that came twice) counts nothing."""
    from aiorobot import SubscriptionEventCallbacks

    s = bare_session(router_port)
    try:
        async with peer_runtime(router_port) as rt:
            node = rt.add_node(Node("listener"))
            got: list[str] = []
            lost: list[tuple[int, int]] = []
            node.create_subscription(
                String, "/chatter", lambda m: got.append(m.data), 100,
                event_callbacks=SubscriptionEventCallbacks(message_lost=lambda e: lost.append((e.total_count, e.total_count_change))),
            )
            key = f"0/chatter/std_msgs::msg::dds_::String_/{STRING_HASH}"
            a, b = bytes(range(16)), bytes(range(16, 32))

            def put(gid: bytes, seq: int, text: str) -> None:
                s.put(key, cdr_string(text), attachment=struct.pack("<qqB", seq, time.time_ns(), 16) + gid)

            seq = 0
            while not got:  # until the subscriber is reachable
                seq += 1
                put(a, seq, "probe")
                await rt_settle()
            for n in (1, 2, 5):  # 3 and 4 never come
                put(a, seq + n, f"a{n}")
            put(b, 1, "b1")  # another publisher: its own numbers
            put(b, 2, "b2")
            put(a, 1, "a again")  # lower numbers (copies that came twice): no loss, and no new start
            put(a, 2, "a again 2")
            put(a, seq + 6, "a6")  # the next after a5: nothing lost
            await wait_until(lambda: "a6" in got)
            await wait_until(lambda: bool(lost))
            await rt.settle()
            assert lost == [(2, 2)]
            stats = rt.transport.statistics()  # type: ignore[attr-defined]
            assert stats.drop_reasons.get("lost") == 2
            said = [r.getMessage() for r in caplog.records if "never arrived" in r.getMessage()]
            assert len(said) == 1 and said[0].startswith("2 samples on /chatter never arrived")
    finally:
        s.close()
