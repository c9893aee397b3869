"""rmw_zenoh's wire format as pure functions: key expressions, liveliness tokens, QoS, GIDs, attachments.

Everything here follows ``docs/design.md`` and ``liveliness_utils.cpp`` /
``attachment_helpers.cpp`` of ros2/rmw_zenoh (Jazzy and later, attachment format of
PR #601), so ROS 2 nodes running ``rmw_zenoh_cpp`` and aiorobot processes see each
other's data and graph.
"""

from __future__ import annotations

import struct
from collections.abc import Callable
from dataclasses import dataclass

from .._core._qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

__all__ = [
    "ATTACHMENT_SIZE",
    "Attachment",
    "TokenInfo",
    "WireError",
    "attachment_gid",
    "attachment_head",
    "attachment_tail",
    "data_key",
    "dds_type",
    "demangle",
    "endpoint_token",
    "gid_of",
    "mangle",
    "node_token",
    "pack_attachment",
    "parse_qos",
    "parse_token",
    "qos_chunk",
    "ros_type",
    "unpack_attachment",
]

ATTACHMENT_SIZE = 33
_HEAD = struct.Struct("<qq")
_GID_SIZE = 16
#: rmw_zenoh's default depth (an empty depth field means it); depth 0 is sent as it too.
_DEFAULT_DEPTH = 42
ENTITY_KINDS = {"NN": "node", "MP": "publisher", "MS": "subscription", "SS": "service", "SC": "client"}


class WireError(ValueError):
    """Bytes or a key expression from the network that do not follow rmw_zenoh's format."""


# -- names ----------------------------------------------------------------------------


def dds_type(type_name: str, *, service: bool = False) -> str:
    """``geometry_msgs/msg/Twist`` -> ``geometry_msgs::msg::dds_::Twist_``."""
    pkg, kind, name = _split_type(type_name)
    return f"{pkg}::{kind}::dds_::{name}_"


def ros_type(dds: str) -> str:
    """``geometry_msgs::msg::dds_::Twist_`` -> ``geometry_msgs/msg/Twist``."""
    parts = dds.split("::")
    if len(parts) != 4 or parts[2] != "dds_" or not parts[3].endswith("_") or len(parts[3]) < 2:
        raise WireError(f"type: expected pkg::msg::dds_::Name_, found {dds!r}")
    return f"{parts[0]}/{parts[1]}/{parts[3][:-1]}"


def _split_type(type_name: str) -> tuple[str, str, str]:
    parts = type_name.split("/")
    if len(parts) != 3 or not all(parts):
        raise ValueError(f"type name: expected pkg/msg/Name, found {type_name!r}")
    return parts[0], parts[1], parts[2]


def data_key(domain_id: int, name: str, type_name: str, type_hash: str) -> str:
    """The key expression of a topic or service: ``<domain>/<name>/<dds_type>/<hash>``."""
    return f"{domain_id}/{name.strip('/')}/{dds_type(type_name)}/{type_hash}"


def mangle(text: str) -> str:
    """A token chunk: every ``/`` becomes ``%``; empty becomes ``%``."""
    return text.replace("/", "%") or "%"


def demangle(chunk: str) -> str:
    return chunk.replace("%", "/")


# -- QoS ------------------------------------------------------------------------------


def qos_chunk(qos: QoSProfile) -> str:
    """rmw_zenoh's ``qos_to_keyexpr``, always with explicit reliability, durability, history, depth."""
    depth = qos.depth if qos.history is HistoryPolicy.KEEP_LAST else 0
    return f"{int(qos.reliability)}:{int(qos.durability)}:{int(qos.history)},{depth}:,:,:,,"


def parse_qos(chunk: str) -> QoSProfile:
    """The inverse of :func:`qos_chunk`; empty fields take rmw_zenoh's defaults."""
    try:
        parts = chunk.split(":")
        if len(parts) != 6:
            raise ValueError("six ':'-separated fields")
        rel = int(parts[0]) if parts[0] else 1
        dur = int(parts[1]) if parts[1] else 2
        hist_s, _, depth_s = parts[2].partition(",")
        hist = int(hist_s) if hist_s else 1
        depth = int(depth_s) if depth_s else _DEFAULT_DEPTH
        if hist == 1 and depth == 0:
            depth = _DEFAULT_DEPTH
        # SYSTEM_DEFAULT (0) and unknown values map to ROS defaults
        return QoSProfile(
            reliability=ReliabilityPolicy(rel if rel in (1, 2) else 1),
            durability=DurabilityPolicy(dur if dur in (1, 2) else 2),
            history=HistoryPolicy(hist if hist in (1, 2) else 1),
            depth=depth,
        )
    except ValueError as err:
        raise WireError(f"QoS chunk: expected R:D:H,depth:dl:ls:L,lease, found {chunk!r} ({err})") from None


# -- liveliness tokens ----------------------------------------------------------------


def node_token(domain_id: int, zid: str, nid: int, enclave: str, namespace: str, name: str) -> str:
    return f"@ros2_lv/{domain_id}/{zid}/{nid}/{nid}/NN/{mangle(enclave)}/{mangle(namespace)}/{name}"


def endpoint_token(
    domain_id: int,
    zid: str,
    nid: int,
    eid: int,
    kind: str,
    enclave: str,
    namespace: str,
    node: str,
    topic: str,
    type_name: str,
    type_hash: str,
    qos: QoSProfile,
) -> str:
    if kind not in ("MP", "MS", "SS", "SC"):
        raise ValueError(f"endpoint kind: expected MP, MS, SS or SC, found {kind!r}")
    return (
        f"@ros2_lv/{domain_id}/{zid}/{nid}/{eid}/{kind}/{mangle(enclave)}/{mangle(namespace)}/{node}/"
        f"{mangle(topic)}/{dds_type(type_name)}/{type_hash}/{qos_chunk(qos)}"
    )


@dataclass(frozen=True, slots=True)
class TokenInfo:
    """A parsed liveliness token."""

    token: str
    domain_id: int
    zid: str
    nid: str
    eid: str
    kind: str  # NN MP MS SS SC
    enclave: str
    namespace: str
    node: str
    topic: str = ""
    type_name: str = ""
    type_hash: str = ""
    qos: QoSProfile | None = None

    @property
    def node_fqn(self) -> str:
        return (self.namespace.rstrip("/") or "") + "/" + self.node

    @property
    def node_key(self) -> tuple[str, str]:
        return (self.zid, self.nid)


def parse_token(token: str) -> TokenInfo:
    """Parse an ``@ros2_lv/...`` token; raises :class:`WireError` naming what is wrong."""
    chunks = token.split("/")
    if len(chunks) < 9 or chunks[0] != "@ros2_lv":
        raise WireError(f"liveliness token: expected @ros2_lv/<domain>/<zid>/<nid>/<id>/<kind>/..., found {token!r}")
    if any(not c for c in chunks):
        raise WireError(f"liveliness token: empty chunk in {token!r}")
    try:
        domain = int(chunks[1])
    except ValueError:
        raise WireError(f"liveliness token: domain {chunks[1]!r} is not an integer in {token!r}") from None
    kind = chunks[5]
    if kind not in ENTITY_KINDS:
        raise WireError(f"liveliness token: unknown entity kind {kind!r} in {token!r}")
    base = dict(
        token=token,
        domain_id=domain,
        zid=chunks[2],
        nid=chunks[3],
        eid=chunks[4],
        kind=kind,
        enclave=demangle(chunks[6]),
        namespace=demangle(chunks[7]),
        node=chunks[8],
    )
    if kind == "NN":
        return TokenInfo(**base)  # type: ignore[arg-type]
    if len(chunks) < 13:  # Rolling may append chunks; tolerate them
        raise WireError(f"liveliness token: expected topic, type, hash and QoS after the node in {token!r}")
    return TokenInfo(
        **base,  # type: ignore[arg-type]
        topic=demangle(chunks[9]),
        type_name=ros_type(chunks[10]),
        type_hash=chunks[11],
        qos=parse_qos(chunks[12]),
    )


def gid_of(token: str) -> bytes:
    """rmw_zenoh's 16-byte GID: XXH3-128 of the token, low then high 64 bits, little endian."""
    import xxhash

    value = xxhash.xxh3_128(token.encode()).intdigest()
    return struct.pack("<QQ", value & 0xFFFF_FFFF_FFFF_FFFF, value >> 64)


# -- attachment -----------------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class Attachment:
    sequence: int
    timestamp_ns: int
    gid: bytes


def attachment_tail(gid: bytes) -> bytes:
    """The part of a publisher's attachments that never changes: the GID length and the GID.

    ``attachment_head(seq, ts) + attachment_tail(gid) == pack_attachment(seq, ts, gid)``; a
    publisher computes the tail once.
    """
    if len(gid) != _GID_SIZE:
        raise ValueError(f"gid: expected {_GID_SIZE} bytes, found {len(gid)}")
    return bytes((_GID_SIZE,)) + gid


#: ``attachment_head(sequence, timestamp_ns)``: the per-message part of an attachment, sequence
#: number and timestamp (16 bytes). The struct's own ``pack``: every put calls it, with no Python
#: frame of its own.
attachment_head: Callable[[int, int], bytes] = _HEAD.pack


def pack_attachment(sequence: int, timestamp_ns: int, gid: bytes) -> bytes:
    """The 33 bytes every put, query and reply carries."""
    return attachment_head(sequence, timestamp_ns) + attachment_tail(gid)


def _check_attachment(data: bytes | None) -> bytes:
    if data is None:
        raise WireError("attachment: expected 33 bytes, found none")
    if len(data) != ATTACHMENT_SIZE:
        raise WireError(f"attachment: expected {ATTACHMENT_SIZE} bytes, found {len(data)}")
    if data[16] != _GID_SIZE:
        raise WireError(f"attachment: expected a GID length of 16, found {data[16]}")
    return data


def unpack_attachment(data: bytes | None) -> Attachment:
    data = _check_attachment(data)
    seq, ts = _HEAD.unpack_from(data)
    return Attachment(seq, ts, bytes(data[17:]))


def attachment_gid(data: bytes | None) -> bytes:
    """The GID of an attachment, checked as :func:`unpack_attachment` checks it (for a receiver
    that needs nothing else)."""
    return bytes(_check_attachment(data)[17:])
