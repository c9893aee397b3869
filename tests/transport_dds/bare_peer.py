"""A bare cyclonedds-python peer that follows ROS 2's DDS conventions, written from them (rmw_cyclonedds,
rmw_dds_common) without aiorobot: the other side of the DDS transport's interop tests.

Run as ``python bare_peer.py``; it reads one JSON command per line on stdin and answers each with
one JSON line on stdout. Domain from ROS_DOMAIN_ID; discovery on localhost only, as
rmw_cyclonedds configures Cyclone for ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST.
"""


import json
import os
import sys
import threading
import time
from dataclasses import asdict, dataclass

from cyclonedds._clayer import ddspy_take, ddspy_write
from cyclonedds.core import InstanceState, SampleState, ViewState
from cyclonedds.builtin import BuiltinDataReader, BuiltinTopicDcpsPublication, BuiltinTopicDcpsSubscription
from cyclonedds.core import Policy, Qos
from cyclonedds.domain import Domain, DomainParticipant
from cyclonedds.idl import IdlStruct
from cyclonedds.idl import types as t
from cyclonedds.pub import DataWriter
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic

INF = (1 << 63) - 1


@dataclass
class Time_(IdlStruct, typename="builtin_interfaces::msg::dds_::Time_"):
    sec: t.int32
    nanosec: t.uint32


@dataclass
class Header_(IdlStruct, typename="std_msgs::msg::dds_::Header_"):
    stamp: Time_
    frame_id: str


@dataclass
class String_(IdlStruct, typename="std_msgs::msg::dds_::String_"):
    data: str


@dataclass
class Int32_(IdlStruct, typename="std_msgs::msg::dds_::Int32_"):
    data: t.int32


@dataclass
class Vector3_(IdlStruct, typename="geometry_msgs::msg::dds_::Vector3_"):
    x: t.float64
    y: t.float64
    z: t.float64


@dataclass
class Twist_(IdlStruct, typename="geometry_msgs::msg::dds_::Twist_"):
    linear: Vector3_
    angular: Vector3_


@dataclass
class Image_(IdlStruct, typename="sensor_msgs::msg::dds_::Image_"):
    header: Header_
    height: t.uint32
    width: t.uint32
    encoding: str
    is_bigendian: t.uint8
    step: t.uint32
    data: t.sequence[t.uint8]


@dataclass
class Gid_(IdlStruct, typename="rmw_dds_common::msg::dds_::Gid_"):
    data: t.array[t.uint8, 16]


@dataclass
class NodeEntitiesInfo_(IdlStruct, typename="rmw_dds_common::msg::dds_::NodeEntitiesInfo_"):
    node_namespace: t.bounded_str[256]
    node_name: t.bounded_str[256]
    reader_gid_seq: t.sequence[Gid_]
    writer_gid_seq: t.sequence[Gid_]


@dataclass
class ParticipantEntitiesInfo_(IdlStruct, typename="rmw_dds_common::msg::dds_::ParticipantEntitiesInfo_"):
    gid: Gid_
    node_entities_info_seq: t.sequence[NodeEntitiesInfo_]


# a service request and reply as rmw_cyclonedds sends them: uint64 guid, int64 seq, then the fields
@dataclass
class AddTwoInts_Request_(IdlStruct, typename="example_interfaces::srv::dds_::AddTwoInts_Request_"):
    guid: t.uint64
    seq: t.int64
    a: t.int64
    b: t.int64


@dataclass
class AddTwoInts_Response_(IdlStruct, typename="example_interfaces::srv::dds_::AddTwoInts_Response_"):
    guid: t.uint64
    seq: t.int64
    sum: t.int64


@dataclass
class UUID_(IdlStruct, typename="unique_identifier_msgs::msg::dds_::UUID_"):
    uuid: t.array[t.uint8, 16]


@dataclass
class Fibonacci_Goal_(IdlStruct, typename="example_interfaces::action::dds_::Fibonacci_Goal_"):
    order: t.int32


@dataclass
class Fibonacci_Sequence_(IdlStruct, typename="example_interfaces::action::dds_::Fibonacci_Result_"):
    sequence: t.sequence[t.int32]


@dataclass
class Fibonacci_SendGoal_Request_(IdlStruct, typename="example_interfaces::action::dds_::Fibonacci_SendGoal_Request_"):
    guid: t.uint64
    seq: t.int64
    goal_id: UUID_
    goal: Fibonacci_Goal_


@dataclass
class Fibonacci_SendGoal_Response_(IdlStruct, typename="example_interfaces::action::dds_::Fibonacci_SendGoal_Response_"):
    guid: t.uint64
    seq: t.int64
    accepted: bool
    stamp: Time_


@dataclass
class Fibonacci_GetResult_Request_(IdlStruct, typename="example_interfaces::action::dds_::Fibonacci_GetResult_Request_"):
    guid: t.uint64
    seq: t.int64
    goal_id: UUID_


@dataclass
class Fibonacci_GetResult_Response_(IdlStruct, typename="example_interfaces::action::dds_::Fibonacci_GetResult_Response_"):
    guid: t.uint64
    seq: t.int64
    status: t.int8
    result: Fibonacci_Sequence_


@dataclass
class Fibonacci_FeedbackMessage_(IdlStruct, typename="example_interfaces::action::dds_::Fibonacci_FeedbackMessage_"):
    goal_id: UUID_
    feedback: Fibonacci_Sequence_


TYPES = {c.__name__.rstrip("_"): c for c in (String_, Int32_, Twist_, Image_, AddTwoInts_Request_, AddTwoInts_Response_)}
HASH_PEI = "RIHS01_91a0593bacdcc50ea9bdcf849a938b128412cc1ea821245c663bcd26f83c295e"

domain_id = int(os.environ.get("ROS_DOMAIN_ID", "0"))
config = (
    "<CycloneDDS><Domain><General><AllowMulticast>false</AllowMulticast></General>"
    "<Discovery><ParticipantIndex>auto</ParticipantIndex><MaxAutoParticipantIndex>32</MaxAutoParticipantIndex>"
    '<Peers><Peer address="localhost"/></Peers></Discovery></Domain></CycloneDDS>'
)
domain = Domain(domain_id, config)
dp = DomainParticipant(domain_id, qos=Qos(Policy.Userdata(b"enclave=/;")))
topics = {}
entities = {}
pubs = BuiltinDataReader(dp, BuiltinTopicDcpsPublication)
subs = BuiltinDataReader(dp, BuiltinTopicDcpsSubscription)
endpoints = {}


def qos(c: dict, hash_: str, extra: str = "") -> Qos:
    depth = c.get("depth", 10)
    history = Policy.History.KeepLast(depth)
    p = [history, Policy.Userdata(f"{extra}typehash={hash_};".encode()) if hash_ else Policy.Userdata(extra.encode())]
    p.append(Policy.Reliability.BestEffort if c.get("best_effort") else Policy.Reliability.Reliable(INF))
    if c.get("deadline_ns"):
        p.append(Policy.Deadline(c["deadline_ns"]))
    if c.get("lifespan_ns"):
        p.append(Policy.Lifespan(c["lifespan_ns"]))
    if c.get("lease_ns"):
        p.append(Policy.Liveliness.ManualByTopic(c["lease_ns"]))
    if c.get("tl"):
        p += [Policy.Durability.TransientLocal, Policy.DurabilityService(0, history, -1, -1, -1)]
    else:
        p.append(Policy.Durability.Volatile)
    if c.get("ignore_local"):
        p.append(Policy.IgnoreLocal.Participant)
    return Qos(*p)


def topic(name: str, cls: type) -> Topic:
    key = (name, cls.__name__)
    if key not in topics:
        topics[key] = Topic(dp, name, cls)
    return topics[key]


def scan() -> None:
    for reader, kind in ((pubs, "writer"), (subs, "reader")):
        for s in reader.take(100):
            if s.sample_info.valid_data:
                ud = s.qos[Policy.Userdata]
                endpoints[str(s.key)] = {
                    "kind": kind, "topic": s.topic_name, "type": s.type_name,
                    "participant": str(s.participant_key), "guid": s.key.bytes.hex(),
                    "userdata": ud.data.decode() if ud is not None else "",
                    "qos": [repr(p) for p in s.qos],
                }


def wait(pred, timeout: float):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        got = pred()
        if got:
            return got
        time.sleep(0.01)
    return None


def handle(c: dict) -> dict:
    op = c["op"]
    if op == "writer":
        cls = TYPES[c["type"]]
        w = DataWriter(dp, topic(c["topic"], cls), qos(c, c.get("hash", ""), c.get("extra", "")))
        entities[c["id"]] = w
        return {"guid": w.guid.bytes.hex()}
    if op == "reader":
        cls = TYPES[c["type"]]
        r = DataReader(dp, topic(c["topic"], cls), qos(c, c.get("hash", ""), c.get("extra", "")))
        entities[c["id"]] = r
        return {"guid": r.guid.bytes.hex()}
    if op == "matched":  # wait until a writer / reader is matched by the other side
        e = entities[c["id"]]
        fn = e.get_matched_subscriptions if isinstance(e, DataWriter) else e.get_matched_publications
        return {"matched": bool(wait(fn, c.get("timeout", 10)))}
    if op == "write":
        entities[c["id"]].write(build(TYPES[c["type"]], c["value"]))
        return {}
    if op == "write_raw":
        return {"ret": ddspy_write(entities[c["id"]]._ref, bytes.fromhex(c["hex"]))}
    if op == "take":
        r = entities[c["id"]]
        got: list = []

        def enough():
            got.extend(r.take(100))
            return len(got) >= c.get("n", 1)

        wait(enough, c.get("timeout", 10))
        return {"samples": [_plain(asdict(s)) for s in got]}
    if op == "take_raw":  # the serialized samples as they arrived, in hex
        r = entities[c["id"]]
        raw: list = []
        mask = SampleState.Any | ViewState.Any | InstanceState.Any
        wait(lambda: raw.extend(d.hex() for d, i in ddspy_take(r._ref, mask, 100) if i.valid_data) or raw, c.get("timeout", 10))
        return {"raw": raw}
    if op == "endpoints":
        def found():
            scan()
            return [e for e in endpoints.values() if e["topic"] == c["topic"] and e["participant"] != str(dp.guid)]

        return {"endpoints": wait(found, c.get("timeout", 10)) or []}
    if op == "announce":  # ros_discovery_info: this participant's one node and its endpoints' GIDs
        w = entities.get("_discovery")
        if w is None:
            w = entities["_discovery"] = DataWriter(
                dp, topic("ros_discovery_info", ParticipantEntitiesInfo_),
                qos({"tl": True, "depth": 1}, HASH_PEI))
        gid = lambda e: Gid_(data=list(entities[e].guid.bytes))  # noqa: E731
        node = NodeEntitiesInfo_(node_namespace=c.get("ns", "/"), node_name=c["node"],
                                 reader_gid_seq=[gid(e) for e in c.get("readers", [])],
                                 writer_gid_seq=[gid(e) for e in c.get("writers", [])])
        w.write(ParticipantEntitiesInfo_(gid=Gid_(data=list(dp.guid.bytes)), node_entities_info_seq=[node]))
        return {}
    if op == "nodes":  # read ros_discovery_info until a node named c["expect"] appears
        r = entities.get("_discovery_reader")
        if r is None:
            q = qos({"tl": True, "depth": 1, "ignore_local": True}, HASH_PEI)
            r = entities["_discovery_reader"] = DataReader(dp, topic("ros_discovery_info", ParticipantEntitiesInfo_), q)
        infos: dict = {}

        def seen():
            for s in r.take(100):
                infos[bytes(s.gid.data).hex()] = [
                    {"name": (n.node_namespace.rstrip("/") + "/" + n.node_name),
                     "writers": [bytes(g.data).hex() for g in n.writer_gid_seq],
                     "readers": [bytes(g.data).hex() for g in n.reader_gid_seq]}
                    for n in s.node_entities_info_seq]
            return any(n["name"] == c["expect"] for ns in infos.values() for n in ns)

        wait(seen, c.get("timeout", 10))
        return {"participants": infos}
    if op == "serve":  # answer AddTwoInts requests with the header copied, for c["n"] requests
        req_r = DataReader(dp, topic(f"rq{c['srv']}Request", AddTwoInts_Request_), qos({}, c["req_hash"], "serviceid=1;"))
        rep_w = DataWriter(dp, topic(f"rr{c['srv']}Reply", AddTwoInts_Response_), qos({}, c["rep_hash"], "serviceid=1;"))
        entities["server_req"], entities["server_rep"] = req_r, rep_w

        def loop():
            served = 0
            while served < c.get("n", 1):
                for s in req_r.take(10):
                    wait(rep_w.get_matched_subscriptions, 5)
                    rep_w.write(AddTwoInts_Response_(guid=s.guid, seq=s.seq, sum=s.a + s.b))
                    served += 1
                time.sleep(0.005)

        threading.Thread(target=loop, daemon=True).start()
        return {"request_reader": req_r.guid.bytes.hex(), "reply_writer": rep_w.guid.bytes.hex()}
    if op == "call":
        req_w = DataWriter(dp, topic(f"rq{c['srv']}Request", AddTwoInts_Request_), qos({}, c["req_hash"], "clientid=7;"))
        rep_r = DataReader(dp, topic(f"rr{c['srv']}Reply", AddTwoInts_Response_), qos({}, c["rep_hash"], "clientid=7;"))
        ok = wait(lambda: req_w.get_matched_subscriptions() and rep_r.get_matched_publications(), 10)
        if not ok:
            return {"error": "no server matched"}
        guid = 0x0102030405060708
        req_w.write(AddTwoInts_Request_(guid=guid, seq=c.get("seq", 1), a=c["a"], b=c["b"]))
        replies: list = []
        wait(lambda: replies.extend(s for s in rep_r.take(10) if s.guid == guid) or replies, 10)
        return {"replies": [{"guid": s.guid, "seq": s.seq, "sum": s.sum} for s in replies]}
    if op == "action_client":  # the endpoints of a Fibonacci action client, matched with the server
        base = c["action"] + "/_action/"
        h = c["hashes"]
        pairs = {}
        for name, req, rep in (("send_goal", Fibonacci_SendGoal_Request_, Fibonacci_SendGoal_Response_),
                               ("get_result", Fibonacci_GetResult_Request_, Fibonacci_GetResult_Response_)):
            w = DataWriter(dp, topic(f"rq{base}{name}Request", req), qos({}, h[name + "_req"], "clientid=8;"))
            r = DataReader(dp, topic(f"rr{base}{name}Reply", rep), qos({}, h[name + "_rep"], "clientid=8;"))
            pairs[name] = (w, r)
        fb = DataReader(dp, topic(f"rt{base}feedback", Fibonacci_FeedbackMessage_), qos({}, h["feedback"]))
        ok = wait(lambda: all(w.get_matched_subscriptions() and r.get_matched_publications() for w, r in pairs.values())
                  and fb.get_matched_publications(), 10)
        if not ok:
            return {"error": "action server not matched"}
        entities["action"] = (pairs, fb)
        return {}
    if op == "action":  # a Fibonacci goal through <action>/_action/{send_goal,get_result,feedback}
        pairs, fb = entities["action"]
        goal_id = UUID_(uuid=list(range(16)))
        guid = 0x1122334455667788

        def call(name, request):
            w, r = pairs[name]
            w.write(request)
            got = []
            wait(lambda: got.extend(s for s in r.take(10) if s.guid == guid) or got, 20)
            return got[0]

        accepted = call("send_goal", Fibonacci_SendGoal_Request_(guid=guid, seq=1, goal_id=goal_id, goal=Fibonacci_Goal_(order=c["order"])))
        result = call("get_result", Fibonacci_GetResult_Request_(guid=guid, seq=2, goal_id=goal_id))
        feedback = [list(s.feedback.sequence) for s in fb.take(100) if bytes(s.goal_id.uuid) == bytes(range(16))]
        return {"accepted": accepted.accepted, "status": result.status, "sequence": list(result.result.sequence), "feedback": feedback}
    if op == "leave":  # leave cleanly: deleting the participant disposes it and its endpoints at once
        dp.__del__()
        return {}
    if op == "guid":
        return {"guid": dp.guid.bytes.hex()}
    raise ValueError(f"unknown op {op!r}")


def build(cls, value):
    """An IdlStruct from plain data, nested structs included."""
    if cls is Twist_:
        return Twist_(linear=Vector3_(**value["linear"]), angular=Vector3_(**value["angular"]))
    if cls is Image_:
        h = value["header"]
        header = Header_(stamp=Time_(**h["stamp"]), frame_id=h["frame_id"])
        return Image_(header=header, **{k: v for k, v in value.items() if k != "header"})
    return cls(**value)


def _plain(v):
    if isinstance(v, dict):
        return {k: _plain(x) for k, x in v.items() if k != "sample_info"}
    if isinstance(v, (list, tuple)):
        return [_plain(x) for x in v]
    if isinstance(v, bytes):
        return list(v)
    return v


print(json.dumps({"ready": True, "guid": dp.guid.bytes.hex()}), flush=True)
for line in sys.stdin:
    if not line.strip():
        continue
    try:
        out = handle(json.loads(line))
    except Exception as err:  # noqa: BLE001 - the test reads the error
        out = {"error": f"{type(err).__name__}: {err}"}
    print(json.dumps(out), flush=True)
