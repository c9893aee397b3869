"""ROS 2's DDS conventions as pure functions: names, USER_DATA, the service header, QoS, discovery range.

What rmw_cyclonedds_cpp (and, for topics and the graph, rmw_fastrtps_cpp) put on the wire,
read from their sources (../shared/INTEROP.md §8 cites each line): ``rt/``/``rq/``/``rr/``
topic names, ``pkg::msg::dds_::Name_`` type names, ``typehash=RIHS01_...;`` in every
endpoint's USER_DATA, the 16-byte request header of services, the rmw QoS -> DDS QoS mapping
and the Cyclone configuration fragment ``ROS_AUTOMATIC_DISCOVERY_RANGE`` stands for. Nothing
here imports cyclonedds: the transport turns :class:`DdsQos` into the binding's ``Qos``.
"""

from __future__ import annotations

import os
import struct
import sys
from dataclasses import dataclass

from .._core._qos import DurabilityPolicy, HistoryPolicy, LivelinessPolicy, QoSProfile, ReliabilityPolicy
from .._core._time import Duration
from ._wire import WireError, dds_type

__all__ = [
    "DISCOVERY_TOPIC",
    "DISCOVERY_TYPE",
    "DdsQos",
    "Endpoint",
    "HEADER",
    "discovery_config",
    "dds_qos",
    "dds_type",
    "parse_endpoint",
    "parse_user_data",
    "profile_of",
    "request_type",
    "service_topics",
    "topic_name",
    "user_data",
]

#: rmw_dds_common's graph topic (no ``rt/`` prefix) and its DDS type name
DISCOVERY_TOPIC = "ros_discovery_info"
DISCOVERY_TYPE = "rmw_dds_common::msg::dds_::ParticipantEntitiesInfo_"
#: rmw_cyclonedds's request header: ``uint64 guid`` then ``int64 seq``, native endian, after the encapsulation
HEADER = struct.Struct("<Qq" if sys.byteorder == "little" else ">Qq")
#: a ``dds_duration_t`` of DDS_INFINITY
INFINITY_NS = (1 << 63) - 1
_UNLIMITED = -1


# -- names ------------------------------------------------------------------------------------


def topic_name(ros_name: str) -> str:
    """``/chatter`` -> ``rt/chatter`` (prefix + the fully qualified name)."""
    return "rt" + ros_name


def service_topics(ros_name: str) -> tuple[str, str]:
    """``/add`` -> (``rq/addRequest``, ``rr/addReply``): the request and reply topics."""
    return f"rq{ros_name}Request", f"rr{ros_name}Reply"


def request_type(srv_type_name: str, part: str) -> str:
    """``example_interfaces/srv/AddTwoInts``, ``Request`` -> ``example_interfaces::srv::dds_::AddTwoInts_Request_``."""
    return dds_type(f"{srv_type_name}_{part}")


@dataclass(frozen=True, slots=True)
class Endpoint:
    """A DDS topic name read back as ROS: ``kind`` is ``topic``, ``request`` or ``reply``."""

    kind: str
    name: str
    type_name: str  # pkg/msg/Name, or for services pkg/srv/Name (Request/Response stripped)


def parse_endpoint(dds_topic: str, dds_type_name: str) -> Endpoint | None:
    """The ROS meaning of a DDS topic and type, or None when they follow no ROS convention
    (``DCPS*``, ``ros_discovery_info``, a plain DDS topic): rmw_cyclonedds's demangling."""
    from ._wire import ros_type

    if dds_topic.startswith("rt/"):
        kind, name = "topic", dds_topic[2:]
    elif dds_topic.startswith("rq/") and dds_topic.endswith("Request"):
        kind, name = "request", dds_topic[2 : -len("Request")]
    elif dds_topic.startswith("rr/") and dds_topic.endswith("Reply"):
        kind, name = "reply", dds_topic[2 : -len("Reply")]
    else:
        return None
    try:
        type_name = ros_type(dds_type_name)
    except WireError:
        return None
    if kind != "topic":
        suffix = "_Request" if kind == "request" else "_Response"
        if not type_name.endswith(suffix):
            return None
        type_name = type_name[: -len(suffix)]
    return Endpoint(kind, name, type_name)


# -- USER_DATA ------------------------------------------------------------------------------


def user_data(type_hash: str, extra: str = "") -> bytes:
    """An endpoint's USER_DATA: ``extra`` (``clientid=...;``) then ``typehash=RIHS01_...;``."""
    return f"{extra}typehash={type_hash};".encode()


def parse_user_data(data: bytes) -> dict[str, str]:
    """rmw's key=value;... grammar; entries that do not follow it are left out."""
    out: dict[str, str] = {}
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        return out
    for item in text.split(";"):
        key, sep, value = item.partition("=")
        if sep and key.isalnum() and value:
            out[key] = value
    return out


# -- QoS ------------------------------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class DdsQos:
    """The DDS QoS rmw_cyclonedds gives an endpoint of ``profile`` (durations in ns)."""

    reliable: bool
    transient_local: bool
    keep_all: bool
    depth: int
    deadline_ns: int | None
    lifespan_ns: int | None
    manual_by_topic: bool
    lease_ns: int


def _ns(value: Duration | None) -> int | None:
    return None if value is None or value.nanoseconds <= 0 else value.nanoseconds


def dds_qos(profile: QoSProfile) -> DdsQos:
    """rmw_cyclonedds's ``create_readwrite_qos``: depth 0 (system default) is keep last 1, lifespan and
    deadline only when set, liveliness lease infinite unless set."""
    keep_all = profile.history is HistoryPolicy.KEEP_ALL
    return DdsQos(
        reliable=profile.reliability is ReliabilityPolicy.RELIABLE,
        transient_local=profile.durability is DurabilityPolicy.TRANSIENT_LOCAL,
        keep_all=keep_all,
        depth=_UNLIMITED if keep_all else max(profile.depth, 1),
        deadline_ns=_ns(profile.deadline),
        lifespan_ns=_ns(profile.lifespan),
        manual_by_topic=profile.liveliness is LivelinessPolicy.MANUAL_BY_TOPIC,
        lease_ns=_ns(profile.liveliness_lease_duration) or INFINITY_NS,
    )


def profile_of(qos: DdsQos) -> QoSProfile:
    """The rmw profile a remote endpoint's DDS QoS stands for (what ``topic info -v`` shows)."""

    def duration(ns: int | None) -> Duration | None:
        return None if ns is None or ns <= 0 or ns >= INFINITY_NS else Duration(nanoseconds=ns)

    return QoSProfile(
        reliability=ReliabilityPolicy.RELIABLE if qos.reliable else ReliabilityPolicy.BEST_EFFORT,
        durability=DurabilityPolicy.TRANSIENT_LOCAL if qos.transient_local else DurabilityPolicy.VOLATILE,
        history=HistoryPolicy.KEEP_ALL if qos.keep_all else HistoryPolicy.KEEP_LAST,
        depth=0 if qos.keep_all else max(qos.depth, 1),
        deadline=duration(qos.deadline_ns),
        lifespan=duration(qos.lifespan_ns),
        liveliness=LivelinessPolicy.MANUAL_BY_TOPIC if qos.manual_by_topic else LivelinessPolicy.AUTOMATIC,
        liveliness_lease_duration=duration(qos.lease_ns),
    )


# -- discovery range ------------------------------------------------------------------------

_RANGES = ("SUBNET", "LOCALHOST", "OFF", "SYSTEM_DEFAULT")


def discovery_config(environ: dict[str, str] | None = None) -> tuple[str, list[str]]:
    """The Cyclone configuration rmw_cyclonedds builds from ``ROS_AUTOMATIC_DISCOVERY_RANGE``,
    ``ROS_STATIC_PEERS`` and ``ROS_LOCALHOST_ONLY``, with ``CYCLONEDDS_URI`` appended as is; and the
    warnings to give (rcl's and rmw_cyclonedds's, one line each)."""
    env = os.environ if environ is None else environ
    warnings: list[str] = []
    raw = env.get("ROS_AUTOMATIC_DISCOVERY_RANGE", "").strip()
    peers = [p.strip() for p in env.get("ROS_STATIC_PEERS", "").split(";") if p.strip()]
    if env.get("ROS_LOCALHOST_ONLY", "").strip() == "1":
        # deprecated in Jazzy but it still wins: localhost, no static peers (rcl init.c)
        if raw or peers:
            warnings.append("ROS_LOCALHOST_ONLY=1 is set: it wins over ROS_AUTOMATIC_DISCOVERY_RANGE and ROS_STATIC_PEERS")
        mode, peers = "LOCALHOST", []
    elif not raw:
        mode = "SUBNET"
    elif raw in _RANGES:
        mode = raw
    else:
        warnings.append(
            f"ROS_AUTOMATIC_DISCOVERY_RANGE: expected one of {', '.join(_RANGES)}, found {raw!r}; using LOCALHOST"
        )
        mode = "LOCALHOST"
    if mode in ("OFF", "SYSTEM_DEFAULT") and peers:
        warnings.append(f"{len(peers)} static peers in ROS_STATIC_PEERS are ignored: discovery range is {mode}")
        peers = []
    localhost = mode == "LOCALHOST"
    no_multicast = mode in ("LOCALHOST", "OFF")
    config = ""
    if localhost or peers or no_multicast:
        config = "<CycloneDDS><Domain>"
        if no_multicast:
            config += "<General><AllowMulticast>false</AllowMulticast></General>"
        if mode == "OFF":
            config += f"<Discovery><ParticipantIndex>none</ParticipantIndex><Tag>ros_discovery_off_{os.getpid()}</Tag>"
        else:
            config += "<Discovery><ParticipantIndex>auto</ParticipantIndex><MaxAutoParticipantIndex>32</MaxAutoParticipantIndex>"
        if localhost or peers:
            addresses = (["localhost"] if localhost else []) + peers
            config += "<Peers>" + "".join(f'<Peer address="{_xml_attr(a)}"/>' for a in addresses) + "</Peers>"
        config += "</Discovery></Domain></CycloneDDS>,"
    config += env.get("CYCLONEDDS_URI", "")
    return config, warnings


def _xml_attr(text: str) -> str:
    return text.replace("&", "&amp;").replace('"', "&quot;").replace("<", "&lt;")
