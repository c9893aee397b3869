"""ROS 2's DDS conventions as aiorobot writes and reads them (pure), and the QoS both ways with a bare peer."""

from __future__ import annotations

import pytest

from aiorobot import Duration, DurabilityPolicy, HistoryPolicy, LivelinessPolicy, Node, QoSProfile, ReliabilityPolicy
from aiorobot.msgs import type_hash
from aiorobot.msgs.std_msgs import String
from aiorobot.transport._dds_wire import (
    HEADER,
    Endpoint,
    dds_qos,
    discovery_config,
    parse_endpoint,
    parse_user_data,
    profile_of,
    service_topics,
    topic_name,
)

from ._helpers import BarePeer, dds_runtime, wait_until

LOCALHOST = (
    "<CycloneDDS><Domain><General><AllowMulticast>false</AllowMulticast></General><Discovery><ParticipantIndex>auto"
    '</ParticipantIndex><MaxAutoParticipantIndex>32</MaxAutoParticipantIndex><Peers><Peer address="localhost"/>'
)


def test_names_follow_rmw_cyclonedds() -> None:
    assert topic_name("/robot/chatter") == "rt/robot/chatter"
    assert service_topics("/add_two_ints") == ("rq/add_two_intsRequest", "rr/add_two_intsReply")
    assert parse_endpoint("rt/robot/chatter", "std_msgs::msg::dds_::String_") == Endpoint("topic", "/robot/chatter", "std_msgs/msg/String")
    assert parse_endpoint("rq/fib/_action/send_goalRequest", "example_interfaces::action::dds_::Fibonacci_SendGoal_Request_") == Endpoint(
        "request", "/fib/_action/send_goal", "example_interfaces/action/Fibonacci_SendGoal")
    assert parse_endpoint("rr/addReply", "example_interfaces::srv::dds_::AddTwoInts_Response_") == Endpoint(
        "reply", "/add", "example_interfaces/srv/AddTwoInts")
    for topic, type_name in (("ros_discovery_info", "rmw_dds_common::msg::dds_::ParticipantEntitiesInfo_"),
                             ("DCPSPublication", "x"), ("rt/chatter", "String"), ("rq/addRequest", "pkg::srv::dds_::Add_Response_")):
        assert parse_endpoint(topic, type_name) is None


def test_the_request_header_is_guid_then_seq_native_endian() -> None:
    # INTEROP §8.4's example: AddTwoInts a=2 b=3 from guid 0x0102030405060708 seq 7
    assert HEADER.pack(0x0102030405060708, 7) == bytes.fromhex("0807060504030201" "0700000000000000")


def test_user_data_is_rmw_key_value() -> None:
    assert parse_user_data(b"clientid= 1.f.2.3.4.5.6.7.8.9.a.b.0.0.0.1;typehash=RIHS01_ab;") == {
        "clientid": " 1.f.2.3.4.5.6.7.8.9.a.b.0.0.0.1", "typehash": "RIHS01_ab"}
    assert parse_user_data(b"typehash=;bad key=1;\xff") == {}


def test_qos_maps_as_rmw_cyclonedds_and_back() -> None:
    profile = QoSProfile(
        reliability=ReliabilityPolicy.BEST_EFFORT, durability=DurabilityPolicy.TRANSIENT_LOCAL, depth=7,
        deadline=Duration(seconds=1), lifespan=Duration(nanoseconds=5_000), liveliness=LivelinessPolicy.MANUAL_BY_TOPIC,
        liveliness_lease_duration=Duration(seconds=2),
    )
    qos = dds_qos(profile)
    assert (qos.reliable, qos.transient_local, qos.keep_all, qos.depth) == (False, True, False, 7)
    assert (qos.deadline_ns, qos.lifespan_ns, qos.manual_by_topic, qos.lease_ns) == (10**9, 5_000, True, 2 * 10**9)
    assert profile_of(qos) == profile
    default = dds_qos(QoSProfile())
    assert (default.deadline_ns, default.lifespan_ns, default.lease_ns) == (None, None, (1 << 63) - 1)
    with pytest.warns(UserWarning):
        assert dds_qos(QoSProfile(depth=0)).depth == 1  # system default depth: keep last 1, as rmw_cyclonedds
    assert dds_qos(QoSProfile(history=HistoryPolicy.KEEP_ALL)).keep_all


def test_discovery_range_becomes_rmw_cyclonedds_config_and_cyclonedds_uri_is_appended() -> None:
    config, warnings = discovery_config({"ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST", "ROS_STATIC_PEERS": "10.0.0.2;robot.local",
                                         "CYCLONEDDS_URI": "file:///etc/cyclone.xml"})
    assert config == LOCALHOST + '<Peer address="10.0.0.2"/><Peer address="robot.local"/></Peers></Discovery></Domain></CycloneDDS>,file:///etc/cyclone.xml'
    assert warnings == []
    assert discovery_config({}) == ("", [])  # SUBNET: Cyclone's defaults (multicast)
    assert discovery_config({"ROS_AUTOMATIC_DISCOVERY_RANGE": "SYSTEM_DEFAULT", "ROS_STATIC_PEERS": "a"})[0] == ""
    off, _ = discovery_config({"ROS_AUTOMATIC_DISCOVERY_RANGE": "OFF"})
    assert "<AllowMulticast>false</AllowMulticast>" in off and "<Tag>ros_discovery_off_" in off and "<Peers>" not in off
    legacy, warnings = discovery_config({"ROS_LOCALHOST_ONLY": "1", "ROS_STATIC_PEERS": "10.0.0.2"})
    assert legacy == LOCALHOST + "</Peers></Discovery></Domain></CycloneDDS>,"
    assert warnings and "ROS_LOCALHOST_ONLY" in warnings[0]
    odd, warnings = discovery_config({"ROS_AUTOMATIC_DISCOVERY_RANGE": "MOON"})
    assert odd.startswith(LOCALHOST) and "expected one of SUBNET, LOCALHOST, OFF, SYSTEM_DEFAULT, found 'MOON'" in warnings[0]


async def test_qos_policies_reach_the_wire_and_come_back(peer: BarePeer, domain_id: int) -> None:
    async with dds_runtime(domain_id) as rt:
        node = rt.add_node(Node("qos"))
        node.create_publisher(String, "/strict", QoSProfile(
            reliability=ReliabilityPolicy.BEST_EFFORT, durability=DurabilityPolicy.TRANSIENT_LOCAL, depth=4,
            deadline=Duration(seconds=3), lifespan=Duration(seconds=4), liveliness=LivelinessPolicy.MANUAL_BY_TOPIC,
            liveliness_lease_duration=Duration(seconds=5)))
        qos = (await peer.cmd(op="endpoints", topic="rt/strict"))["endpoints"][0]["qos"]
        await peer.cmd(op="writer", id="w", topic="rt/theirs", type="String", hash=type_hash(String), best_effort=True,
                       tl=True, depth=3, deadline_ns=6 * 10**9, lifespan_ns=7 * 10**9, lease_ns=8 * 10**9)
        await wait_until(lambda: bool(rt.graph.publishers_of("/theirs")))
        theirs = rt.graph.publishers_of("/theirs")[0].qos
    assert "Policy.Reliability.BestEffort" in qos and "Policy.Durability.TransientLocal" in qos
    assert "Policy.History.KeepLast(depth=4)" in qos
    assert "Policy.Deadline(deadline=3000000000)" in qos and "Policy.Lifespan(lifespan=4000000000)" in qos
    assert "Policy.Liveliness.ManualByTopic(lease_duration=5000000000)" in qos
    assert any(p.startswith("Policy.DurabilityService(") and "KeepLast(depth=4)" in p for p in qos)
    assert theirs == QoSProfile(
        reliability=ReliabilityPolicy.BEST_EFFORT, durability=DurabilityPolicy.TRANSIENT_LOCAL, depth=3,
        deadline=Duration(seconds=6), lifespan=Duration(seconds=7), liveliness=LivelinessPolicy.MANUAL_BY_TOPIC,
        liveliness_lease_duration=Duration(seconds=8))


def test_a_config_file_may_choose_the_dds_transport() -> None:
    from aiorobot.launch import parse_config

    config = parse_config({"runtime": {"transport": "dds"}, "nodes": [{"use": "aiorobot.examples.sensor:ImuPublisher"}]})
    assert config.runtime.transport == "dds"


async def test_a_configuration_cyclone_refuses_is_one_config_error_and_nothing_opens(domain_id: int) -> None:
    from aiorobot import Runtime
    from aiorobot.transport import DdsConfigError, DdsTransport

    transport = DdsTransport(domain_id=domain_id, config="<CycloneDDS><Domain><Bogus>1</Bogus></Domain></CycloneDDS>")
    with pytest.raises(DdsConfigError, match=r"^DdsTransport\(config=\): Cyclone DDS refused the configuration of domain"):
        async with Runtime(transport=transport, handle_signals=False):
            pass
    assert transport.guid == b"" and transport.bus is None


async def test_the_cli_says_in_one_line_that_cyclonedds_uri_is_unusable(domain_id: int) -> None:
    import asyncio
    import sys

    from ._helpers import dds_env

    env = dds_env(domain_id) | {"CYCLONEDDS_URI": "file:///nonexistent/cyclone.xml"}
    proc = await asyncio.create_subprocess_exec(
        sys.executable, "-m", "aiorobot.cli", "node", "list", "--transport", "dds",
        stdout=asyncio.subprocess.PIPE, stderr=asyncio.subprocess.PIPE, env=env)
    out, err = await proc.communicate()
    lines = [line for line in err.decode().splitlines() if line.startswith("CYCLONEDDS_URI")]
    assert proc.returncode == 2 and out == b""
    assert len(lines) == 1 and "Cyclone DDS refused the configuration" in lines[0] and "Traceback" not in err.decode()
