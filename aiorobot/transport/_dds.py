"""The DDS transport: a runtime's bus extended to a ROS 2 graph of rmw_cyclonedds / rmw_fastrtps nodes.

It speaks ROS 2's DDS conventions (``_dds_wire``) on eclipse-cyclonedds's Python binding, the
C library rmw_cyclonedds_cpp uses, and works like the zenoh transport:

* a local publisher's topic gets one DDS writer (``rt/<name>``), fed by a hidden *sender tap* on
  the bus that serialises to CDR (aiorobot's, byte-exact with ROS 2's) and hands the bytes to
  the writer; same-process subscribers keep zero-copy delivery;
* a local subscription's topic gets one DDS reader (ignoring this participant's own writers); the
  CDR taken from it is decoded on Cyclone's thread and published into the bus by an *injector*;
* remote endpoints, learnt from DDS's built-in topics (DCPSPublication / DCPSSubscription, with
  their QoS and the ``typehash`` of their USER_DATA) and named after the node that
  ``ros_discovery_info`` lists their GID under, join the bus as endpoints of their own, so
  ``Runtime.graph``, the QoS and type checks, ``count_subscribers`` and ``wait_for_service`` see
  them as local ones;
* services are ``rq/<name>Request`` / ``rr/<name>Reply`` with rmw_cyclonedds's request header.

One DomainParticipant per transport (a runtime; rmw has one per process, which is the same for
a process with one runtime). Malformed input from the network is dropped with a throttled
warning and counted in :meth:`DdsTransport.statistics`; it never reaches user code.
"""

from __future__ import annotations

import asyncio
import itertools
import logging
import os
import threading
import time
from collections import Counter
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from .._core._errors import ConfigError, ServiceError
from .._core._pubsub import Publisher, Subscription, Tap, deliver_eagerly
from .._core._qos import QoSProfile, ReliabilityPolicy
from .._core._services import Client, Service, _Call, _reply
from .._core._transport import Transport
from ._dds_types import idl_request, idl_struct
from ._dds_wire import (
    DISCOVERY_TOPIC,
    HEADER,
    DdsQos,
    dds_qos,
    discovery_config,
    parse_endpoint,
    parse_user_data,
    profile_of,
    service_topics,
    topic_name,
    user_data,
)
from .._core._handoff import post
from ..msgs._cdr import decoder
from ._zenoh import _FALLBACK_QOS, ZenohTransport, _ignore, _Injector, _own_tap, _Owner, _RemoteClient, _RemoteServer, delivery_loop

if TYPE_CHECKING:
    from .._core._bus import Bus
    from .._core._graph import NodeInfo
    from .._core._node import Node

__all__ = ["DdsConfigError", "DdsStatistics", "DdsTransport"]

_log = logging.getLogger("aiorobot.transport")

#: how long a call or a reply waits for the other side's reader to be matched before it is written
MATCH_TIMEOUT_SEC = 5.0
#: Cyclone's DDS_RETCODE_PRECONDITION_NOT_MET: the domain exists in this process already
_PRECONDITION_NOT_MET = -4
#: samples taken from a reader per listener call
_TAKE_MAX = 256
_SERVICE_QOS = QoSProfile()
_ANY_QOS = QoSProfile(reliability=ReliabilityPolicy.BEST_EFFORT, depth=1)


class DdsConfigError(ConfigError, ValueError):
    """Cyclone refused its configuration (``CYCLONEDDS_URI``, the discovery variables, or
    ``DdsTransport(config=)``): ``path`` names where it came from. Nothing was opened; Cyclone's own
    line on stderr names the element at fault."""


@dataclass(frozen=True, slots=True)
class DdsStatistics:
    """What a DDS transport has sent, received and dropped."""

    sent: int
    received: int
    dropped: int
    drop_reasons: dict[str, int]
    remote_nodes: int


def _cyclone_qos(qos: DdsQos, data: bytes, *, reader: bool) -> Any:
    """The binding's ``Qos`` for ``qos`` (rmw_cyclonedds's ``create_readwrite_qos``), XCDR1 as ROS 2 needs."""
    from cyclonedds.core import Policy, Qos

    from ._dds_wire import INFINITY_NS

    history = Policy.History.KeepAll if qos.keep_all else Policy.History.KeepLast(qos.depth)
    policies: list[Any] = [
        history,
        Policy.Reliability.Reliable(INFINITY_NS) if qos.reliable else Policy.Reliability.BestEffort,
        Policy.Userdata(data),
        Policy.DataRepresentation(use_cdrv0_representation=True),
        Policy.WriterDataLifecycle(autodispose=False),
    ]
    if qos.transient_local:
        policies += [
            Policy.Durability.TransientLocal,
            Policy.DurabilityService(0, history, -1, -1, -1),
        ]
    else:
        policies.append(Policy.Durability.Volatile)
    if qos.lifespan_ns is not None:
        policies.append(Policy.Lifespan(qos.lifespan_ns))
    if qos.deadline_ns is not None:
        policies.append(Policy.Deadline(qos.deadline_ns))
    liveliness = Policy.Liveliness.ManualByTopic if qos.manual_by_topic else Policy.Liveliness.Automatic
    policies.append(liveliness(qos.lease_ns))
    if reader:
        policies.append(Policy.IgnoreLocal.Participant)
        policies.append(Policy.TypeConsistency.AllowTypeCoercion(ignore_member_names=True))
    return Qos(*policies)


def _dds_qos_of(qos: Any) -> DdsQos:
    """A discovered endpoint's QoS (the binding's ``Qos``) as :class:`DdsQos`."""
    from cyclonedds.core import Policy

    from ._dds_wire import INFINITY_NS

    history = qos[Policy.History]
    durability = qos[Policy.Durability]
    liveliness = qos[Policy.Liveliness]
    deadline = qos[Policy.Deadline]
    lifespan = qos[Policy.Lifespan]
    keep_all = history is Policy.History.KeepAll
    return DdsQos(
        reliable=isinstance(qos[Policy.Reliability], Policy.Reliability.Reliable),
        transient_local=durability in (Policy.Durability.TransientLocal, Policy.Durability.Transient,
                                       Policy.Durability.Persistent),
        keep_all=keep_all,
        depth=-1 if keep_all or history is None else history.depth,
        deadline_ns=None if deadline is None or deadline.deadline >= INFINITY_NS else deadline.deadline,
        lifespan_ns=None if lifespan is None or lifespan.lifespan >= INFINITY_NS else lifespan.lifespan,
        manual_by_topic=isinstance(liveliness, Policy.Liveliness.ManualByTopic),
        lease_ns=INFINITY_NS if liveliness is None else liveliness.lease_duration,
    )


def _merged(old: QoSProfile | None, new: QoSProfile, *, reader: bool) -> QoSProfile:
    """One DDS endpoint serves every local endpoint of a topic: the deepest history, transient local
    if any wants it; reliable if any writer is (a reader: only if every subscription is)."""
    if old is None:
        return new
    from dataclasses import replace

    from .._core._qos import DurabilityPolicy, HistoryPolicy

    reliability = (
        (old.reliability if new.reliability is old.reliability else ReliabilityPolicy.BEST_EFFORT)
        if reader
        else (ReliabilityPolicy.RELIABLE if ReliabilityPolicy.RELIABLE in (old.reliability, new.reliability) else old.reliability)
    )
    durability = (
        DurabilityPolicy.TRANSIENT_LOCAL
        if DurabilityPolicy.TRANSIENT_LOCAL in (old.durability, new.durability)
        else DurabilityPolicy.VOLATILE
    )
    history = HistoryPolicy.KEEP_ALL if HistoryPolicy.KEEP_ALL in (old.history, new.history) else HistoryPolicy.KEEP_LAST
    return replace(old, reliability=reliability, durability=durability, history=history, depth=max(old.depth, new.depth))


def _pad(data: bytes) -> bytes:
    """CDR handed to Cyclone is padded to a multiple of 4, as cyclonedds-python's own writer does."""
    extra = -len(data) % 4
    return data + b"\0" * extra if extra else data


class _Outbound:
    """One topic's DDS writer, fed by a hidden tap on the bus."""

    def __init__(self, transport: DdsTransport, topic: str, msg_type: Any, type_hash: str) -> None:
        self.transport = transport
        self.topic = topic
        self.msg_type = msg_type
        self.type_hash = type_hash
        self.publishers: list[Publisher[Any]] = []
        self.qos: QoSProfile | None = None
        self.writer: Any = None
        self.tap = Tap(msg_type, topic, _ANY_QOS, self._send, owner="<dds>", keeps=False)
        self.tap.hidden = True  # type: ignore[attr-defined]
        self.tap.echo_of = transport._owner  # type: ignore[attr-defined]  # (its injectors skip it)

    def declare(self, qos: QoSProfile) -> None:
        merged = _merged(self.qos, qos, reader=False)
        if self.writer is not None and merged == self.qos:
            return
        from cyclonedds.pub import DataWriter

        transport = self.transport
        old = self.writer
        self.qos = merged
        cq = _cyclone_qos(dds_qos(merged), user_data(self.type_hash), reader=False)
        self.writer = DataWriter(transport._participant, transport._topic(topic_name(self.topic), idl_struct(self.msg_type)), cq)
        if old is not None:
            transport._forget_gid(old)
            old.__del__()

    def _send(self, msg: Any) -> None:
        """The tap's callback: runs in the publishing thread."""
        transport = self.transport
        from cyclonedds._clayer import ddspy_write

        from ..msgs import serialize

        try:
            data = serialize(msg)
        except (TypeError, ValueError) as err:
            transport._warn("serialize", f"cannot send a message on {self.topic}: {err}")
            return
        writer = self.writer
        if writer is None:
            return
        ret = ddspy_write(writer._ref, _pad(data))
        if ret < 0:
            transport._warn("write", f"Cyclone refused a message on {self.topic} (return code {ret})")
        else:
            transport._sent += 1


class _Inbound:
    """One topic's DDS reader; hands checked, decoded messages to the bus."""

    def __init__(self, transport: DdsTransport, topic: str, msg_type: Any, type_hash: str) -> None:
        self.transport = transport
        self.topic = topic
        self.msg_type = msg_type
        self.type_hash = type_hash
        self.subscriptions: list[Subscription[Any]] = []
        self.qos: QoSProfile | None = None
        self.reader: Any = None
        self.fallback = _Injector(transport._owner, msg_type, topic, _FALLBACK_QOS, "<dds>", hidden=True)
        self.decode = decoder(msg_type)

    def declare(self, qos: QoSProfile) -> None:
        merged = _merged(self.qos, qos, reader=True)
        if self.reader is not None and merged == self.qos:
            return
        transport = self.transport
        old = self.reader
        self.qos = merged
        cq = _cyclone_qos(dds_qos(merged), user_data(self.type_hash), reader=True)
        self.reader = transport._reader(topic_name(self.topic), idl_struct(self.msg_type), cq, self._on_data)
        if old is not None:
            transport._forget_gid(old)
            old.__del__()

    def _on_data(self, reader: Any) -> None:
        """On a Cyclone thread: take, check and decode, then hand over to the loop the topic's
        subscriptions run on (the priority loop's when one runs there, else the main loop)."""
        transport = self.transport
        decode = self.decode
        loop = delivery_loop(self.subscriptions, transport._loop)  # the priority loop's, if one subscribes
        for data, info in transport._take(reader):
            if not info.valid_data:
                continue
            handle = info.publication_handle
            if handle in transport._blocked:
                transport._warn("type_hash", f"dropped a sample on {self.topic} from a writer whose type hash differs")
                continue
            try:
                msg = decode(data)
            except Exception as err:  # noqa: BLE001 - nothing from the network may escape
                transport._drop_sample(f"rt{self.topic}", err)
                continue
            transport._received += 1
            if loop is not None:
                post(loop, deliver_eagerly, transport._inject, self, handle, msg)  # (callbacks run at once)


class _ServiceSide:
    """A local server's request reader and reply writer."""

    def __init__(self, transport: DdsTransport, service: Service) -> None:
        self.transport = transport
        self.service = service
        srv = service.srv_type
        request_topic, reply_topic = service_topics(service.srv_name)
        extra = f"serviceid={transport._endpoint_id()};"
        qos = dds_qos(_SERVICE_QOS)
        req_hash, rep_hash = transport._hash(srv.Request), transport._hash(srv.Response)
        self.reader = transport._reader(
            request_topic, idl_request(srv, "Request"), _cyclone_qos(qos, user_data(req_hash, extra), reader=True), self._on_request
        )
        from cyclonedds.pub import DataWriter

        self.writer = DataWriter(
            transport._participant, transport._topic(reply_topic, idl_request(srv, "Response")),
            _cyclone_qos(qos, user_data(rep_hash, extra), reader=False),
        )

    def _on_request(self, reader: Any) -> None:
        transport = self.transport
        from ..msgs import deserialize

        for data, info in transport._take(reader):
            if not info.valid_data:
                continue
            try:
                guid, seq = HEADER.unpack_from(data, 4)
                request = deserialize(data[:4] + data[4 + HEADER.size :], self.service.srv_type.Request)
            except Exception as err:  # noqa: BLE001 - nothing from the network may escape
                transport._warn("request", f"dropped a request on rq{self.service.srv_name}Request: {err}")
                continue
            transport._received += 1
            transport._to_loop(transport._serve, self, info.publication_handle, guid, seq, request)

    def close(self) -> None:
        for entity in (self.reader, self.writer):
            self.transport._forget_gid(entity)
            entity.__del__()


class _ClientSide:
    """The request writer and reply reader calls of one service name and type go through."""

    def __init__(self, transport: DdsTransport, srv_type: Any, name: str) -> None:
        self.transport = transport
        self.srv_type = srv_type
        self.name = name
        self.guid = int.from_bytes(os.urandom(8), "little")
        self.seq = itertools.count(1)
        self.pending: dict[int, _Call] = {}
        request_topic, reply_topic = service_topics(name)
        extra = f"clientid={transport._endpoint_id()};"
        qos = dds_qos(_SERVICE_QOS)
        from cyclonedds.pub import DataWriter

        self.reader = transport._reader(
            reply_topic, idl_request(srv_type, "Response"),
            _cyclone_qos(qos, user_data(transport._hash(srv_type.Response), extra), reader=True), self._on_reply,
        )
        self.writer = DataWriter(
            transport._participant, transport._topic(request_topic, idl_request(srv_type, "Request")),
            _cyclone_qos(qos, user_data(transport._hash(srv_type.Request), extra), reader=False),
        )

    def matched(self) -> bool:
        """The server's request reader and reply writer both see this client."""
        return bool(self.writer.get_matched_subscriptions()) and bool(self.reader.get_matched_publications())

    def _on_reply(self, reader: Any) -> None:
        transport = self.transport
        from ..msgs import deserialize

        for data, info in transport._take(reader):
            if not info.valid_data or len(data) < 4 + HEADER.size:
                continue
            guid, seq = HEADER.unpack_from(data, 4)
            if guid != self.guid:
                continue  # another client's reply (every client of the name reads the reply topic)
            try:
                response = deserialize(data[:4] + data[4 + HEADER.size :], self.srv_type.Response)
            except Exception as err:  # noqa: BLE001
                transport._warn("reply", f"dropped a reply on rr{self.name}Reply: {err}")
                transport._to_loop(self._fail, seq, f"service {self.name} sent a malformed reply: {err}")
                continue
            transport._received += 1
            transport._to_loop(self._answer, seq, response)

    def _answer(self, seq: int, response: Any) -> None:
        call = self.pending.pop(seq, None)
        if call is not None:
            _reply(call, result=response)

    def _fail(self, seq: int, text: str) -> None:
        call = self.pending.pop(seq, None)
        if call is not None:
            _reply(call, exc=ServiceError(text))

    def close(self) -> None:
        for call in self.pending.values():
            _reply(call, exc=ServiceError(f"service {self.name}: the transport closed before the reply"))
        self.pending.clear()
        for entity in (self.reader, self.writer):
            self.transport._forget_gid(entity)
            entity.__del__()


@dataclass
class _RemoteNode:
    info: NodeInfo
    gids: frozenset[bytes]


class DdsTransport(Transport):
    """Joins a ROS 2 graph on DDS (rmw_cyclonedds_cpp; rmw_fastrtps_cpp for topics and the graph).

    Parameters
    ----------
    domain_id
        The DDS domain (``ROS_DOMAIN_ID``).
    config
        A Cyclone configuration (XML fragments and ``file://`` URIs, comma separated) used instead
        of the one built from ``ROS_AUTOMATIC_DISCOVERY_RANGE`` / ``ROS_STATIC_PEERS`` /
        ``ROS_LOCALHOST_ONLY`` and ``CYCLONEDDS_URI``.
    enclave
        The participant's ``enclave=`` USER_DATA (``/``).
    """

    name = "dds"

    def __init__(self, *, domain_id: int = 0, config: str | None = None, enclave: str = "/") -> None:
        super().__init__(domain_id=domain_id)
        self.config = config
        self.enclave = enclave
        self._domain: Any = None
        self._participant: Any = None
        self._guid = b""
        self._loop: asyncio.AbstractEventLoop | None = None
        self._owner: _Owner = None  # type: ignore[assignment]
        self._lock = threading.RLock()
        self._ids = itertools.count(1)
        self._topics: dict[tuple[str, str], Any] = {}
        self._outbound: dict[tuple[str, str], _Outbound] = {}
        self._inbound: dict[tuple[str, str], _Inbound] = {}
        self._services: dict[int, _ServiceSide] = {}
        self._clients: dict[tuple[str, str], _ClientSide] = {}
        self._local_nodes: dict[int, Node] = {}
        self._endpoint_gids: dict[int, tuple[Node, set[bytes]]] = {}  # id(endpoint) -> (its node, its DDS entities' GIDs)
        self._remote: dict[bytes, Any] = {}  # remote endpoint GUID -> what it added to the bus (None: nothing)
        self._clientids: dict[int, str] = {}  # remote request writer's publication handle -> its clientid
        self._by_gid: dict[int, _Injector] = {}  # publication handle -> injector
        self._handle_of: dict[bytes, int] = {}
        self._blocked: set[int] = set()
        self._participants: dict[bytes, list[_RemoteNode]] = {}
        self._gid_node: dict[bytes, str] = {}
        self._builtin: list[Any] = []
        self._discovery_writer: Any = None
        self._discovery_reader: Any = None
        self._announce_pending = False
        self._sent = 0
        self._received = 0
        self._drops: Counter[str] = Counter()
        self._last_warning: dict[str, float] = {}
        self._hashes: dict[Any, str] = {}
        self._warned_types: set[str] = set()

    def __repr__(self) -> str:
        state = f"guid={self._guid.hex()}" if self._participant is not None else "closed"
        return f"<DdsTransport domain_id={self.domain_id} {state} remote_nodes={len(self.remote_nodes())}>"

    # -- participant ---------------------------------------------------------------------

    async def open(self, bus: Bus) -> None:
        try:
            import cyclonedds  # noqa: F401
        except ImportError as err:
            raise RuntimeError(f"the dds transport needs cyclonedds (pip install 'cyclonedds>=11,<12'): {err}") from None
        config, warnings = (self.config, []) if self.config is not None else discovery_config()
        for text in warnings:
            _log.warning(text)
        await asyncio.to_thread(self._open_domain, config)  # a bad configuration: DdsConfigError, nothing opened
        await super().open(bus)
        self._loop = asyncio.get_running_loop()
        self._owner = _Owner(self._loop, threading.get_ident(), "<dds>")
        await asyncio.to_thread(self._open_participant)
        bus.services.listener = self  # type: ignore[attr-defined]

    def _open_domain(self, config: str) -> None:
        from cyclonedds.core import DDSException
        from cyclonedds.domain import Domain

        try:
            self._domain = Domain(self.domain_id, config)
        except DDSException as err:
            if err.code == _PRECONDITION_NOT_MET:
                self._domain = None  # this process already has the domain (another runtime): shared as it is
                return
            if self.config is not None:
                where = "DdsTransport(config=)"
            elif os.environ.get("CYCLONEDDS_URI", "").strip():
                where = "CYCLONEDDS_URI"
            else:
                where = "ROS_AUTOMATIC_DISCOVERY_RANGE / ROS_STATIC_PEERS"
            shown = config if len(config) <= 200 else config[:200] + "..."
            raise DdsConfigError(
                where, None, f"Cyclone DDS refused the configuration of domain {self.domain_id} ({shown!r}): "
                "expected a file:// URI or <CycloneDDS> XML it accepts; its own line above names what is wrong",
            ) from None

    def _open_participant(self) -> None:
        from cyclonedds.builtin import (
            BuiltinDataReader,
            BuiltinTopicDcpsParticipant,
            BuiltinTopicDcpsPublication,
            BuiltinTopicDcpsSubscription,
        )
        from cyclonedds.core import Policy, Qos
        from cyclonedds.domain import DomainParticipant
        from cyclonedds.pub import DataWriter

        from ..msgs.rmw_dds_common import ParticipantEntitiesInfo

        self._participant = DomainParticipant(self.domain_id, qos=Qos(Policy.Userdata(f"enclave={self.enclave};".encode())))
        self._guid = self._participant.guid.bytes
        info_type = idl_struct(ParticipantEntitiesInfo)
        qos = QoSProfile(durability=1, depth=1)  # reliable, transient local, keep last 1 (rmw_dds_common)
        data = user_data(self._hash(ParticipantEntitiesInfo))
        self._discovery_writer = DataWriter(
            self._participant, self._topic(DISCOVERY_TOPIC, info_type), _cyclone_qos(dds_qos(qos), data, reader=False)
        )
        reader_qos = dds_qos(QoSProfile(durability=1, history=2, depth=0))  # keep all
        self._discovery_reader = self._reader(DISCOVERY_TOPIC, info_type, _cyclone_qos(reader_qos, data, reader=True), self._on_discovery)
        kinds = {BuiltinTopicDcpsParticipant: "participant", BuiltinTopicDcpsPublication: "writer",
                 BuiltinTopicDcpsSubscription: "reader"}
        for topic, kind in kinds.items():
            self._builtin.append(_with_listener(
                lambda listener, t=topic: BuiltinDataReader(self._participant, t, listener=listener),
                lambda r, k=kind: self._on_builtin(r, k),
            ))
        self._announce()

    async def close(self) -> None:
        participant = self._participant
        if participant is None:
            return
        bus = self.bus
        with self._lock:
            for guid in list(self._remote):
                self._forget(guid)
            for out in self._outbound.values():
                if bus is not None:
                    bus.remove(out.tap)
            for inb in self._inbound.values():
                if bus is not None:
                    bus.remove(inb.fallback)
            for side in [*self._services.values(), *self._clients.values()]:
                side.close()
            self._outbound.clear()
            self._inbound.clear()
            self._services.clear()
            self._clients.clear()
        if bus is not None and getattr(bus.services, "listener", None) is self:
            bus.services.listener = None  # type: ignore[attr-defined]
        self._participant = None
        await asyncio.to_thread(self._delete, participant)
        await super().close()

    def _delete(self, participant: Any) -> None:
        participant.__del__()  # deletes every reader, writer and topic of the participant
        if self._domain is not None:
            self._domain.__del__()
            self._domain = None

    @property
    def guid(self) -> bytes:
        """The participant's GUID (the ``gid`` this process announces on ``ros_discovery_info``)."""
        return self._guid

    def statistics(self) -> DdsStatistics:
        return DdsStatistics(self._sent, self._received, sum(self._drops.values()), dict(self._drops), len(self.remote_nodes()))

    def remote_nodes(self) -> tuple[NodeInfo, ...]:
        return tuple(n.info for nodes in self._participants.values() for n in nodes)

    # -- helpers ---------------------------------------------------------------------------

    # The bus side is the zenoh transport's: throttled, counted warnings; the hop to the main loop;
    # cached type hashes; a received message published into the bus by its remote publisher's
    # injector (``_by_gid``: here keyed by the DDS publication handle); a remote endpoint joined to it.
    _warn = ZenohTransport._warn
    _drop_sample = ZenohTransport._drop_sample
    _to_loop = ZenohTransport._to_loop
    _hash = ZenohTransport._hash
    _add_to_bus = ZenohTransport._add_to_bus

    def _inject(self, inbound: Any, gid: Any, msg: Any) -> None:
        """On the main loop: publish a received message into the bus as its remote publisher (the
        writer's own injector when its graph entry is known, else the topic's fallback)."""
        injector = self._by_gid.get(gid)
        if injector is None or injector.topic_name != inbound.topic or injector.msg_type is not inbound.msg_type:
            injector = inbound.fallback
        if injector.destroyed:
            return
        try:
            injector.publish(msg)  # (not to the outbound taps: see _Injector._set_targets)
        except Exception as err:  # noqa: BLE001
            self._warn("inject", f"could not deliver a message on {inbound.topic}: {err}")

    def _endpoint_id(self) -> str:
        """rmw_cyclonedds's ``clientid``/``serviceid``: the participant GUID prefix and a counter, as
        ``" 1.f.…"`` (hex bytes joined by ``.``, the first padded to width 2)."""
        raw = self._guid[:12] + next(self._ids).to_bytes(4, "big")
        return f"{raw[0]:2x}." + ".".join(f"{b:x}" for b in raw[1:])

    def _topic(self, name: str, idl: Any) -> Any:
        from cyclonedds.topic import Topic

        key = (name, idl.__idl_typename__)
        topic = self._topics.get(key)
        if topic is None:
            topic = self._topics[key] = Topic(self._participant, name, idl)
        return topic

    def _reader(self, name: str, idl: Any, qos: Any, on_data: Any) -> Any:
        from cyclonedds.sub import DataReader

        return _with_listener(lambda listener: DataReader(self._participant, self._topic(name, idl), qos, listener=listener), on_data)

    @staticmethod
    def _take(reader: Any) -> list[tuple[bytes, Any]]:
        from cyclonedds._clayer import ddspy_take
        from cyclonedds.core import InstanceState, SampleState, ViewState

        ret = ddspy_take(reader._ref, SampleState.Any | ViewState.Any | InstanceState.Any, _TAKE_MAX)
        return [] if isinstance(ret, int) else ret

    # -- graph: ros_discovery_info -----------------------------------------------------------

    def _track(self, endpoint: Any, *entities: Any) -> None:
        """Announce ``entities`` (DDS readers/writers) as ``endpoint``'s under its node."""
        node = getattr(endpoint, "node", None)
        if node is None or isinstance(node, _Owner):
            return
        self._local_nodes.setdefault(id(node), node)
        self._endpoint_gids.setdefault(id(endpoint), (node, set()))[1].update(e.guid.bytes for e in entities)
        self._announce_soon()

    def _untrack(self, endpoint: Any) -> None:
        self._endpoint_gids.pop(id(endpoint), None)
        self._announce_soon()

    def _forget_gid(self, entity: Any) -> None:
        """A DDS entity was replaced or deleted: no endpoint announces it any more."""
        gid = entity.guid.bytes
        for _node, gids in self._endpoint_gids.values():
            gids.discard(gid)

    def _announce_soon(self) -> None:
        if not self._announce_pending and self._loop is not None:
            self._announce_pending = True
            self._to_loop(self._announce)

    def _announce(self) -> None:
        """Publish this participant's whole state (every node with its readers' and writers' GIDs)."""
        self._announce_pending = False
        if self._participant is None:
            return
        from cyclonedds._clayer import ddspy_write

        from ..msgs import serialize
        from ..msgs.rmw_dds_common import Gid, NodeEntitiesInfo, ParticipantEntitiesInfo

        readers = self._reader_gids()
        nodes = []
        with self._lock:
            for node in self._local_nodes.values():
                gids = set().union(*(g for n, g in self._endpoint_gids.values() if n is node))
                nodes.append(NodeEntitiesInfo(
                    node_namespace=node.get_namespace() or "/", node_name=node.get_name(),
                    reader_gid_seq=[Gid(data=list(g)) for g in sorted(gids) if g in readers],
                    writer_gid_seq=[Gid(data=list(g)) for g in sorted(gids) if g not in readers],
                ))
        info = ParticipantEntitiesInfo(gid=Gid(data=list(self._guid)), node_entities_info_seq=nodes)
        ddspy_write(self._discovery_writer._ref, _pad(serialize(info)))

    def _reader_gids(self) -> set[bytes]:
        out = {inb.reader.guid.bytes for inb in self._inbound.values() if inb.reader is not None}
        out |= {s.reader.guid.bytes for s in self._services.values()}
        out |= {c.reader.guid.bytes for c in self._clients.values()}
        return out

    def _on_discovery(self, reader: Any) -> None:
        from ..msgs import deserialize
        from ..msgs.rmw_dds_common import ParticipantEntitiesInfo

        for data, info in self._take(reader):
            if not info.valid_data:
                continue
            try:
                msg = deserialize(data, ParticipantEntitiesInfo)
            except Exception as err:  # noqa: BLE001
                self._warn("discovery", f"dropped a malformed {DISCOVERY_TOPIC} sample: {err}")
                continue
            self._to_loop(self._participant_info, msg)

    def _participant_info(self, msg: Any) -> None:
        """On the main loop: a participant's nodes replace what it said before."""
        from .._core._graph import NodeInfo

        gid = bytes(msg.gid.data)
        if gid == self._guid:
            return
        nodes = []
        for n in msg.node_entities_info_seq:
            ns = n.node_namespace or "/"
            fqn = ns.rstrip("/") + "/" + n.node_name
            gids = frozenset(bytes(g.data) for g in (*n.reader_gid_seq, *n.writer_gid_seq))
            nodes.append(_RemoteNode(NodeInfo(n.node_name, ns, fqn, "remote"), gids))
        with self._lock:
            self._participants[gid] = nodes
            for node in nodes:
                for g in node.gids:
                    self._gid_node[g] = node.info.fully_qualified_name
            for guid, entry in self._remote.items():  # endpoints learnt before their node was named
                name = self._gid_node.get(guid)
                if entry is not None and name is not None:
                    _rename(entry, name)

    # -- graph: DDS built-in topics ---------------------------------------------------------------

    def _on_builtin(self, reader: Any, kind: str) -> None:
        """On a Cyclone thread (or the creating thread for this participant's own endpoints)."""
        try:
            samples = reader.take(_TAKE_MAX)
        except Exception as err:  # noqa: BLE001
            self._warn("discovery", f"could not read DDS discovery data: {err}")
            return
        for s in samples:
            alive = bool(s.sample_info.valid_data)
            self._to_loop(self._endpoint_event, kind, s, alive)

    def _endpoint_event(self, kind: str, s: Any, alive: bool) -> None:
        """On the main loop: a remote reader or writer appeared or left."""
        if self.bus is None:
            return
        guid = s.key.bytes
        with self._lock:
            if kind == "participant":
                if not alive and self._participants.pop(guid, None) is not None:  # its nodes leave the graph
                    for gid in [g for g, _ in self._gid_node.items() if g[:12] == guid[:12]]:
                        del self._gid_node[gid]
                return
            if not alive:
                self._clientids.pop(s.sample_info.instance_handle, None)
                self._forget(guid)
                return
            if kind == "writer" and (s.topic_name or "").startswith("rq/"):
                clientid = parse_user_data(_user_data_of(s)).get("clientid")
                if clientid is not None:
                    self._clientids[s.sample_info.instance_handle] = clientid
            if s.participant_key.bytes == self._guid or guid in self._remote:
                return
            parsed = parse_endpoint(s.topic_name or "", s.type_name or "")
            if parsed is None:
                return  # DCPS*, ros_discovery_info, a plain DDS topic
            try:
                self._learn(guid, kind, parsed, s)
            except Exception as err:  # noqa: BLE001 - a bad peer must not break discovery
                self._remote[guid] = None
                self._warn("discovery", f"could not add remote {kind} on {s.topic_name}: {err}")

    def _learn(self, guid: bytes, kind: str, parsed: Any, s: Any) -> None:
        from ..msgs import get

        bus = self.bus
        assert bus is not None
        self._remote[guid] = None
        node = self._gid_node.get(guid, "<unknown node>")
        try:
            cls = get(parsed.type_name)
        except Exception:
            if parsed.type_name not in self._warned_types:
                self._warned_types.add(parsed.type_name)
                _log.info(f"remote {kind} on {parsed.name} uses {parsed.type_name}, which this process does not know: not connected")
            return
        if parsed.kind != "topic":
            part = "Request" if parsed.kind == "request" else "Response"
            cls_hash = self._hash(getattr(cls, part))
        else:
            cls_hash = self._hash(cls)
        found = parse_user_data(_user_data_of(s)).get("typehash")
        if found is not None and found != cls_hash:
            if kind == "writer":
                self._blocked.add(s.sample_info.instance_handle)
            self._warn(
                "type_hash",
                f"type mismatch on {parsed.name}: remote {kind} of {node} uses {s.type_name} with hash {found}, "
                f"this process has {cls_hash}: they do not connect",
            )
            return
        qos = profile_of(_dds_qos_of(s.qos))
        if parsed.kind == "topic" and kind == "writer":
            injector = _Injector(self._owner, cls, parsed.name, qos, node)
            self._remote[guid] = injector
            handle = s.sample_info.instance_handle
            self._by_gid[handle] = injector
            self._handle_of[guid] = handle
            self._add_to_bus(injector)
        elif parsed.kind == "topic":
            tap = Tap(cls, parsed.name, qos, _ignore, owner=node, keeps=False)
            self._remote[guid] = tap
            self._add_to_bus(tap)
        elif parsed.kind == "request" and kind == "reader":
            server = _RemoteServer(self, cls, parsed.name, "", node)  # type: ignore[arg-type]
            self._remote[guid] = server
            bus.services.add(server)  # type: ignore[arg-type]
        elif parsed.kind == "request":
            client = _RemoteClient(parsed.type_name, parsed.name, node)
            self._remote[guid] = client
            bus.services.add(client)  # type: ignore[arg-type]

    def _forget(self, guid: bytes) -> None:
        entry = self._remote.pop(guid, None)
        handle = self._handle_of.pop(guid, None)
        if handle is not None:
            self._by_gid.pop(handle, None)
        bus = self.bus
        if entry is None or bus is None:
            return
        entry.destroyed = True
        if isinstance(entry, (_Injector, Tap)):
            bus.remove(entry)
        else:
            bus.services.remove(entry)

    # -- nodes -----------------------------------------------------------------------------------

    def node_added(self, node: Node) -> None:
        with self._lock:
            self._local_nodes[id(node)] = node
        self._announce_soon()

    def node_removed(self, node: Node) -> None:
        with self._lock:
            self._local_nodes.pop(id(node), None)
        self._announce_soon()

    # -- local endpoints ------------------------------------------------------------------------

    def endpoint_added(self, endpoint: Any) -> None:
        if self._participant is None or isinstance(endpoint, _Injector) or _own_tap(endpoint):
            return
        with self._lock:
            if isinstance(endpoint, Publisher):
                self._add_publisher(endpoint)
            elif isinstance(endpoint, (Subscription, Tap)):
                self._add_subscription(endpoint)
            elif isinstance(endpoint, Service):
                side = self._services[id(endpoint)] = _ServiceSide(self, endpoint)
                self._track(endpoint, side.reader, side.writer)
            elif isinstance(endpoint, Client):
                side = self._client_side(endpoint.srv_type, endpoint.srv_name)
                self._track(endpoint, side.writer, side.reader)

    def endpoint_removed(self, endpoint: Any) -> None:
        if self._participant is None or isinstance(endpoint, _Injector) or _own_tap(endpoint):
            return
        with self._lock:
            self._untrack(endpoint)
            if isinstance(endpoint, Publisher):
                key = (endpoint.topic_name, endpoint.type_name)
                out = self._outbound.get(key)
                if out is not None and endpoint in out.publishers:
                    out.publishers.remove(endpoint)
                    if not out.publishers:
                        del self._outbound[key]
                        if self.bus is not None:
                            self.bus.remove(out.tap)
                        out.writer.__del__()
            elif isinstance(endpoint, (Subscription, Tap)):
                key = (endpoint.topic_name, endpoint.type_name)
                inb = self._inbound.get(key)
                if inb is not None and endpoint in inb.subscriptions:
                    inb.subscriptions.remove(endpoint)
                    if not inb.subscriptions:
                        del self._inbound[key]
                        if self.bus is not None:
                            self.bus.remove(inb.fallback)
                        inb.reader.__del__()
            elif isinstance(endpoint, Service):
                side = self._services.pop(id(endpoint), None)
                if side is not None:
                    side.close()

    def _add_publisher(self, pub: Publisher[Any]) -> None:
        key = (pub.topic_name, pub.type_name)
        out = self._outbound.get(key)
        new = out is None
        if out is None:
            out = self._outbound[key] = _Outbound(self, pub.topic_name, pub.msg_type, self._hash(pub.msg_type))
        out.declare(pub.qos)
        out.publishers.append(pub)
        for p in out.publishers:
            self._track(p, out.writer)
        if new and self.bus is not None:
            self.bus.add_subscription(out.tap)

    def _add_subscription(self, sub: Subscription[Any]) -> None:
        key = (sub.topic_name, sub.type_name)
        inb = self._inbound.get(key)
        new = inb is None
        if inb is None:
            inb = self._inbound[key] = _Inbound(self, sub.topic_name, sub.msg_type, self._hash(sub.msg_type))
        inb.subscriptions.append(sub)
        if new and self.bus is not None:
            self.bus.add_publisher(inb.fallback)
        inb.declare(sub.qos)
        for s in inb.subscriptions:
            self._track(s, inb.reader)

    # -- services ------------------------------------------------------------------------------

    def _serve(self, side: _ServiceSide, handle: int, guid: int, seq: int, request: Any) -> None:
        """On the main loop: serve a remote request like a local call, then write the reply once the
        caller's reply reader is matched (as rmw_cyclonedds's server waits for it)."""
        loop = asyncio.get_running_loop()
        future: asyncio.Future[Any] = loop.create_future()
        service = side.service

        def done(fut: asyncio.Future[Any]) -> None:
            if fut.cancelled() or fut.exception() is not None:
                err = "cancelled" if fut.cancelled() else fut.exception()
                _log.error(f"service {service.srv_name} failed a remote request: {err}; DDS has no error reply, none is sent")
                return
            if self._caller_matched(side, handle):
                self._write_reply(side, guid, seq, fut.result())  # now: before what after_reply() queued
            else:
                loop.create_task(self._reply_when_matched(side, handle, guid, seq, fut.result()))

        future.add_done_callback(done)
        service.node._call_soon(service._enqueue, _Call(request, loop, future, guid.to_bytes(8, "little") + bytes(8), seq))

    def _caller_matched(self, side: _ServiceSide, handle: int) -> bool:
        """The reply writer has matched the caller's reply reader: the reader with the ``clientid`` of the
        request's writer, or any reader when that writer gave none (rmw_cyclonedds's server test)."""
        matched = side.writer.get_matched_subscriptions()
        clientid = self._clientids.get(handle)
        if clientid is None or not matched:
            return bool(matched)
        for reader in matched:
            data = side.writer.get_matched_subscription_data(reader)
            if data is not None and parse_user_data(_user_data_of(data)).get("clientid") == clientid:
                return True
        return False

    async def _reply_when_matched(self, side: _ServiceSide, handle: int, guid: int, seq: int, response: Any) -> None:
        if await _until(lambda: self._caller_matched(side, handle)):
            self._write_reply(side, guid, seq, response)
        else:
            self._warn("reply", f"no reply reader for a request on {side.service.srv_name}: reply dropped")

    def _write_reply(self, side: _ServiceSide, guid: int, seq: int, response: Any) -> None:
        from ..msgs import serialize

        try:
            data = serialize(response)
        except Exception as err:  # noqa: BLE001
            self._warn("reply", f"could not answer a request on {side.service.srv_name}: {err}")
            return
        if self._participant is not None:
            self._write(side.writer, data, guid, seq)

    def _write(self, writer: Any, cdr: bytes, guid: int, seq: int) -> None:
        """Write ``cdr`` with the request header (guid, seq) after its encapsulation."""
        from cyclonedds._clayer import ddspy_write

        ret = ddspy_write(writer._ref, _pad(cdr[:4] + HEADER.pack(guid, seq) + cdr[4:]))
        if ret < 0:
            self._warn("write", f"Cyclone refused a service message (return code {ret})")
        else:
            self._sent += 1

    def _client_side(self, srv_type: Any, name: str) -> _ClientSide:
        key = (name, srv_type.__msgtype__)
        side = self._clients.get(key)
        if side is None:
            side = self._clients[key] = _ClientSide(self, srv_type, name)
        return side

    def _query(self, server: _RemoteServer, call: _Call) -> None:
        """Send ``call`` to a remote server (on the caller's loop); the reply completes it."""
        with self._lock:
            side = self._client_side(server.srv_type, server.srv_name)
        self._to_loop(lambda: asyncio.get_running_loop().create_task(self._send_request(side, call)))

    async def _send_request(self, side: _ClientSide, call: _Call) -> None:
        from ..msgs import serialize

        if not await _until(side.matched):
            _reply(call, exc=ServiceError(f"service {side.name}: its server did not match this client within {MATCH_TIMEOUT_SEC} s"))
            return
        try:
            data = serialize(call.request)
        except Exception as err:  # noqa: BLE001
            _reply(call, exc=ServiceError(f"service {side.name}: could not send the request: {err}"))
            return
        seq = next(side.seq)
        side.pending[seq] = call
        self._write(side.writer, data, side.guid, seq)


def _with_listener(make: Any, on_data: Any) -> Any:
    """A reader made by ``make(listener)`` whose ``on_data(reader)`` runs for each arrival. Cyclone may
    call the listener while the reader is being created, before the binding knows the entity: what
    arrives then is taken once the reader exists."""
    from cyclonedds.core import Listener

    made: list[Any] = []

    def call(_entity: Any) -> None:
        if made:
            on_data(made[0])

    reader = make(Listener(on_data_available=call))
    made.append(reader)
    on_data(reader)
    return reader


async def _until(predicate: Any) -> bool:
    """Poll ``predicate`` until true or MATCH_TIMEOUT_SEC (matching is Cyclone's, it has no awaitable)."""
    deadline = time.monotonic() + MATCH_TIMEOUT_SEC
    delay = 0.001
    while not predicate():
        if time.monotonic() >= deadline:
            return False
        await asyncio.sleep(delay)
        delay = min(delay * 2, 0.02)
    return True


def _user_data_of(endpoint: Any) -> bytes:
    """A discovered endpoint's USER_DATA (empty when it has none)."""
    from cyclonedds.core import Policy

    found = endpoint.qos[Policy.Userdata]
    return found.data if found is not None else b""


def _rename(entry: Any, node: str) -> None:
    """A remote endpoint's node became known (``ros_discovery_info`` came after DCPSPublication)."""
    if isinstance(entry, Tap):
        entry.owner = node
    elif hasattr(entry, "remote"):
        entry.remote = node
