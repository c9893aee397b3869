"""The zenoh transport: a runtime's bus extended to other processes and machines, rmw_zenoh's way.

* A local publisher gets an rmw_zenoh liveliness token; its topic gets one zenoh
  publisher fed by a hidden *sender tap* on the bus, which serialises to CDR in the
  publishing thread and puts with the 33-byte attachment (only while a remote
  subscriber matches). Same-process subscribers keep zero-copy delivery: they never
  see the tap.
* A local subscription gets a token; its topic gets one zenoh subscriber (an
  advanced one with history for transient local). zenoh's thread checks each sample
  (key, type hash, attachment, CDR) and decodes it (arrays as views into the payload),
  queues it in the inbox of the loop the topic's subscriptions run on (arrival order)
  and wakes that loop once per batch; there it is published into the bus by an
  *injector* (a publisher standing for the remote one), a topic's depth at most per
  loop turn, and an idle subscription's plain-function callback runs right then.
* ``iceoryx2_topics``: large messages between processes on one host go over
  iceoryx2 beside zenoh (:mod:`aiorobot.transport._iceoryx2`).
* Remote endpoints learnt from liveliness tokens join the bus as endpoints of their
  own (injectors for publishers, passive taps for subscriptions, remote servers and
  clients for services), so ``Runtime.graph``, ``count_subscribers``,
  ``wait_for_service`` and the QoS-incompatibility warnings see them exactly as
  local ones.
* Services are queryables declared ``complete=True``; calls are queries.

Malformed input from the network is dropped with a throttled warning and counted
in :meth:`ZenohTransport.statistics`; it never reaches user code.
"""

from __future__ import annotations

import asyncio
import itertools
import json
import logging
import os
import struct
import threading
import time
from collections import Counter, deque
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from .._core._handoff import post
from .._core._pubsub import EagerBatch, Publisher, Subscription, Tap
from .._core._qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from .._core._services import Client, Service, _Call, _reply
from .._core._errors import ServiceError
from .._core._transport import Transport
from ..msgs import DeserializationError as _DeserializationError
from ..msgs._cdr import decoder
from ..msgs import serialize as _serialize
from ._diagnose import NOTHING_LISTENS, host_port, why_unreachable
from ._session_config import (
    SessionPlan,
    ZenohConfigError,
    ZenohSessionError,
    allowed_plain,
    apply_overrides,
    check_plan,
    load_config_file,
    plan_of,
    zenoh_error_text,
)
from ._wire import (
    ATTACHMENT_SIZE,
    WireError,
    attachment_gid,
    attachment_head,
    attachment_tail,
    data_key,
    dds_type,
    endpoint_token,
    gid_of,
    node_token,
    pack_attachment,
    parse_token,
    unpack_attachment,
)

if TYPE_CHECKING:
    from .._core._bus import Bus
    from .._core._graph import NodeInfo
    from .._core._node import Node

__all__ = ["TransportStatistics", "ZenohTransport", "build_session_config"]

_log = logging.getLogger("aiorobot.transport")

DEFAULT_CONNECT = "tcp/127.0.0.1:7447"
DEFAULT_LISTEN = "tcp/127.0.0.1:0"
#: A service query waits this long at most on the zenoh side (callers time out on their own).
QUERY_TIMEOUT_SEC = 24 * 3600.0
WARN_INTERVAL_SEC = 1.0
#: How long a remote node has to describe a type this process does not know (``~/get_type_description``).
DESCRIBE_TIMEOUT_SEC = 5.0
#: Queries for one type that a node serving get_type_description left unanswered (its queryable's
#: route not up yet): asked again 0.05 s later, doubling up to 2 s, this many times in all.
DESCRIBE_ATTEMPTS = 8
#: rmw_zenoh's defaults: a 48 MiB shared-memory pool per session, used for messages of 2 KiB and more
#: (``ZENOH_SHM_ALLOC_SIZE`` and ``ZENOH_SHM_MESSAGE_SIZE_THRESHOLD`` change them, in bytes)
SHM_ALLOC_SIZE = 48 * 1024 * 1024
SHM_THRESHOLD = 2 * 1024
SHM_MIN_CHECK = 1024  # smaller payloads are never in shared memory here: skip asking
#: ``SessionPlan.source`` of a session made without a config file
DEFAULT_SOURCE = "the default session config"
#: the "no zenoh router" warning is given once a process
_router_warned = threading.Event()
#: received samples the transport holds for the main loop at most (a loop that stalled for longer than
#: this many messages loses the oldest, counted as ``backlog`` drops); KEEP_LAST subscriptions keep their depth
BACKLOG_LIMIT = 10_000
#: samples of one topic the main loop injects before it lets the subscriptions' dispatchers run
#: (fewer when the topic's smallest depth is smaller), and of all topics together
MAX_CHUNK = 64
MAX_DRAIN = 256
#: samples of one topic zenoh holds for the loop to take (:class:`_Puller`), in a ring: a loop
#: that falls further behind loses the oldest (reported as ``lost``, from the gap they leave in
#: their publisher's sequence numbers) and zenoh's receiving thread never waits for it, so the
#: session's other topics (the priority loop's among them) keep flowing. A small one costs the
#: burst: with a blocking channel of 4,096 the bench's 20,000-Twist burst took 82k msgs/s and
#: 10.1 us of Python CPU per message, with 16,384 108k and 7.8 us. A loop that stalls
#: (``STALL_SEC``) has its samples taken by the thread instead
PULL_CAPACITY = 16384
#: a loop that took none of a pulling topic's samples for this long (twice in a row) is stalled
STALL_SEC = 0.005
#: a topic received over iceoryx2 and zenoh both delivers each (publisher, sequence number) once
#: among this many of the publisher's newest
WINDOW = 256
_SEQ = struct.Struct("<q")
_ANY_QOS = QoSProfile(reliability=ReliabilityPolicy.BEST_EFFORT, depth=1)
_FALLBACK_QOS = QoSProfile(durability=DurabilityPolicy.TRANSIENT_LOCAL, depth=1)


def _env_bytes(name: str, default: int) -> int:
    raw = os.environ.get(name, "").strip()
    if not raw:
        return default
    try:
        value = int(raw)
    except ValueError:
        value = -1
    if value <= 0:
        raise ValueError(f"{name}: expected a size in bytes (a positive integer), found {raw!r}")
    return value


@dataclass(frozen=True, slots=True)
class TransportStatistics:
    """What a zenoh transport has sent, received and dropped."""

    sent: int
    received: int
    dropped: int
    drop_reasons: dict[str, int]
    remote_nodes: int
    #: of ``sent``, the messages put through zenoh's shared memory (large ones, when it is enabled)
    sent_shm: int = 0
    #: of ``received``, the messages that arrived in shared memory (from a peer on this host)
    received_shm: int = 0
    #: connect endpoints the session could not link to when it opened (each one warned about,
    #: except the default router of a session that has peer endpoints of its own)
    connect_failures: int = 0
    #: messages sent over iceoryx2 to processes on this host (``iceoryx2_topics``), not counted in ``sent``
    sent_iceoryx2: int = 0
    #: messages received over iceoryx2, not counted in ``received``
    received_iceoryx2: int = 0


class _Owner:
    """The stand-in node of endpoints the transport adds to the bus (they run on the main loop)."""

    def __init__(self, loop: asyncio.AbstractEventLoop, thread_id: int, name: str) -> None:
        self._loop = loop
        self._thread_id = thread_id
        self._name = name

    def get_fully_qualified_name(self) -> str:
        return self._name

    def _call_soon(self, fn: Any, *args: Any) -> None:
        fn(*args)

    def get_logger(self) -> logging.Logger:
        return _log


class _Injector(Publisher):  # type: ignore[type-arg]
    """Publishes into the bus what a remote publisher sent; its node name is the remote node's."""

    def __init__(
        self,
        owner: _Owner,
        msg_type: Any,
        topic: str,
        qos: QoSProfile,
        remote: str,
        *,
        hidden: bool = False,
        fresh: bool = False,
    ) -> None:
        super().__init__(owner, msg_type, topic, qos)  # type: ignore[arg-type]
        self.remote = remote
        self.hidden = hidden
        #: What it publishes was decoded with ``view=True``: a new message nobody else holds, in
        #: the form subscribers get (read-only arrays and sequences), so it needs no copy.
        self.fresh = fresh
        if hidden:
            self._history = None

    def _set_targets(self, subs: tuple[Any, ...], *, leaving: Any = None) -> None:
        """What it publishes came from its transport: that transport's outbound taps (marked with
        ``echo_of``, its stand-in node) are left out, so nothing received is sent back. Set up
        once per change of the topic's endpoints, not tested per message on the send path."""
        own = self.node
        super()._set_targets(tuple(s for s in subs if getattr(s, "echo_of", None) is not own), leaving=leaving)

    def _accept(self, msg: Any) -> Any:
        if not self.fresh or self._guard is not None:  # (debug_messages: the read-only twin)
            return super()._accept(msg)
        self.published += 1
        return msg

    @property
    def node_name(self) -> str:
        return self.remote

    def __repr__(self) -> str:
        return f"<remote publisher {self.topic_name} {self.type_name} of {self.remote}>"


class _RemoteServer:
    """A service server in another process, as the local registry sees it."""

    kind = "service"

    def __init__(self, transport: ZenohTransport, srv_type: Any, name: str, key: str, node_name: str) -> None:
        self.transport = transport
        self.node = transport._owner
        self.srv_type = srv_type
        self.srv_name = name
        self.key = key
        self.remote = node_name
        self.destroyed = False

    @property
    def type_name(self) -> str:
        return str(self.srv_type.__msgtype__)

    @property
    def node_name(self) -> str:
        return self.remote

    def is_idle(self) -> bool:
        return True

    def __repr__(self) -> str:
        return f"<remote service {self.srv_name} {self.type_name} of {self.remote}>"

    def _enqueue(self, call: _Call) -> None:
        self.transport._query(self, call)


class _RemoteClient:
    kind = "client"

    def __init__(self, type_name: str, name: str, node_name: str) -> None:
        self._type_name = type_name
        self.srv_name = name
        self.remote = node_name
        self.destroyed = False

    @property
    def type_name(self) -> str:
        return self._type_name

    @property
    def node_name(self) -> str:
        return self.remote


@dataclass
class _LocalNode:
    nid: int
    token: Any
    endpoints: int = 0


class _Outbound:
    """One topic's zenoh publisher, fed by a hidden tap on the bus.

    Everything a put needs that does not change per message (key, attachment tail with the
    GID, QoS, the shared-memory threshold) is settled here once; :meth:`_send` only
    serialises, stamps and puts.
    """

    def __init__(self, transport: ZenohTransport, topic: str, msg_type: Any, type_hash: str) -> None:
        self.transport = transport
        self.topic = topic
        self.msg_type = msg_type
        self.type_hash = type_hash
        self.key = data_key(transport.domain_id, topic, msg_type.__msgtype__, type_hash)
        self.publishers: list[Publisher[Any]] = []
        self._tail = attachment_tail(b"\0" * 16)
        self._seq = itertools.count(1)
        self.zpub: Any = None
        self.advanced = False
        self.matched = False  # a remote subscriber matches the key (kept by zenoh's matching listener)
        self.depth = 0
        self.iox: Any = None  # the iceoryx2 sender (iceoryx2_topics)
        # a remote subscription of the topic is not served over iceoryx2: large messages go over zenoh too
        self.zenoh_needed = True
        self.said = False  # which way large messages go was logged
        self.tap = Tap(msg_type, topic, _ANY_QOS, self._send, owner="<zenoh>", keeps=False)
        self.tap.hidden = True  # type: ignore[attr-defined]
        self.tap.echo_of = transport._owner  # type: ignore[attr-defined]  # (its injectors skip it)

    def set_gid(self, gid: bytes) -> None:
        """The GID every put's attachment carries (that of the topic's first local publisher)."""
        self._tail = attachment_tail(gid)
        self.transport._own_gids.add(gid)

    def declare(self, qos: QoSProfile) -> None:
        """(Re)declare the zenoh publisher so it serves ``qos`` (a cache for transient local)."""
        import zenoh
        import zenoh.ext

        session = self.transport._session
        want_cache = qos.durability is DurabilityPolicy.TRANSIENT_LOCAL
        depth = qos.depth if qos.history is HistoryPolicy.KEEP_LAST else 1000
        if self.zpub is not None and (self.advanced or not want_cache) and depth <= self.depth:
            return
        reliable = qos.reliability is ReliabilityPolicy.RELIABLE
        kwargs: dict[str, Any] = dict(
            reliability=zenoh.Reliability.RELIABLE if reliable else zenoh.Reliability.BEST_EFFORT,
            congestion_control=(
                zenoh.CongestionControl.BLOCK
                if reliable and qos.history is HistoryPolicy.KEEP_ALL
                else zenoh.CongestionControl.DROP
            ),
            allowed_destination=zenoh.Locality.REMOTE,
        )
        old = self.zpub
        if want_cache or self.advanced:
            self.depth = max(depth, self.depth)
            self.matched = True
            self.zpub = zenoh.ext.declare_advanced_publisher(
                session,
                self.key,
                cache=zenoh.ext.CacheConfig(max_samples=self.depth),
                publisher_detection=True,
                sample_miss_detection=(
                    zenoh.ext.MissDetectionConfig(heartbeat=None, sporadic_heartbeat=0.5) if reliable else None
                ),
                **kwargs,
            )
            self.advanced = True
        else:
            self.depth = max(depth, self.depth)
            zpub = session.declare_publisher(self.key, **kwargs)
            # no remote subscriber matches: nothing to serialise (zenoh would drop the put); an
            # advanced publisher's cache needs every message, so it has no listener
            zpub.declare_matching_listener(self._on_matching)
            self.matched = zpub.matching_status.matching
            self.zpub = zpub
        if old is not None:
            old.undeclare()

    def _on_matching(self, status: Any) -> None:
        if not self.advanced:
            self.matched = status.matching

    def _send(self, msg: Any) -> None:
        """The tap's callback: runs in the publishing thread."""
        transport = self.transport
        zpub = self.zpub
        if zpub is None:
            return  # closed
        iox = self.iox
        if iox is not None and iox.wanted():
            self._send_iceoryx2(msg, iox, zpub)
            return
        if not self.matched and not zpub.matching_status.matching:
            return  # no remote subscriber (asked, as the listener's word may still be on its way)
        try:
            data = _serialize(msg)
        except (TypeError, ValueError) as err:
            transport._warn("serialize", f"cannot send a message on {self.topic}: {err}")
            return
        attachment = attachment_head(next(self._seq), time.time_ns()) + self._tail
        zpub.put(data if len(data) < transport._shm_from else transport._payload(data), attachment=attachment)
        transport._sent += 1

    def _send_iceoryx2(self, msg: Any, iox: Any, zpub: Any) -> None:
        """A message of a topic with an iceoryx2 input of another process connected: a large one
        goes over iceoryx2, and over zenoh only for remote subscriptions that path does not serve."""
        transport = self.transport
        try:
            parts, size = iox.serialize(msg)
        except (TypeError, ValueError) as err:
            transport._warn("serialize", f"cannot send a message on {self.topic}: {err}")
            return
        attachment = attachment_head(next(self._seq), time.time_ns()) + self._tail
        if size >= transport._shm_threshold:
            why = iox.send(attachment, parts, size)
            if why is None:
                transport._sent_iox += 1
                if not self.zenoh_needed:
                    return
            else:  # it goes over zenoh, as to any other subscriber
                transport._warn("iceoryx2", f"cannot send a message on {self.topic} over iceoryx2 ({why}): sent over zenoh")
        if not self.matched and not zpub.matching_status.matching:
            return
        data = b"".join(parts)
        zpub.put(data if len(data) < transport._shm_from else transport._payload(data), attachment=attachment)
        transport._sent += 1

    def close(self) -> None:
        if self.zpub is not None:
            self.zpub.undeclare()
            self.zpub = None
        if self.iox is not None:
            self.iox.close()
            self.iox = None


class Delivered:
    """Which messages of each publisher were delivered, by sequence number: a topic received two
    ways (over iceoryx2 and zenoh; a transient-local topic's history from zenoh-ext and from the
    transport's own query) delivers each message once, the copy that comes second dropped.

    The ``window`` newest numbers of each publisher are remembered (``WINDOW`` at least; a
    transient-local topic's depth); an older one counts as delivered. A copy is dropped only for a
    publisher marked as reaching this inbound two ways (``seen(..., twice=True)``): one that sends
    over zenoh alone (an rmw_zenoh node, another host) is never second-guessed on its numbers.

    ``lost`` counts the numbers that left the window never delivered, from the first one seen of
    each publisher on (``seen(..., count=True)``; an iceoryx2 topic's: its messages may come either
    way and out of order, so a number is given up only once ``window`` newer ones came)."""

    def __init__(self, window: int = 0) -> None:
        # GID -> [newest sequence number, window bits, may come twice, first number counted]
        self._by_gid: dict[bytes, list[int]] = {}
        self._window = max(window, WINDOW)
        self.lost = 0

    @property
    def window(self) -> int:
        return self._window

    @window.setter
    def window(self, value: int) -> None:
        if value > self._window:  # (a deeper subscription): numbers past the old window were counted
            for entry in self._by_gid.values():
                entry[3] = max(entry[3], entry[0] - self._window + 1)
        self._window = max(value, self._window)

    def seen(self, gid: bytes, seq: int, twice: bool = False, count: bool = False) -> bool:
        """Whether ``seq`` of ``gid`` was delivered already; if not, it is from now on. ``twice``:
        this copy came a way that makes ``gid`` a publisher whose messages may come twice;
        ``count``: count the numbers this one pushes out of the window undelivered in ``lost``."""
        entry = self._by_gid.get(gid)
        if entry is None:
            self._by_gid[gid] = [seq, 1, twice, seq]
            return False
        if twice:
            entry[2] = True
        newest, bits, both, first = entry
        window = self.window
        if seq > newest:
            shift = seq - newest
            if count and seq - window >= first:  # numbers first.. leave the window: count the undelivered
                lo, hi = max(newest - window + 1, first), min(newest, seq - window)
                if hi >= lo:  # these were in the window: their bits say which came
                    width = hi - lo + 1
                    self.lost += width - ((bits >> (newest - hi)) & ((1 << width) - 1)).bit_count()
                self.lost += max(0, seq - window - newest)  # these never were (newest >= first)
            entry[0], entry[1] = seq, ((bits << shift) | 1) & ((1 << window) - 1) if shift < window else 1
            return False
        back = newest - seq
        if back >= window or bits >> back & 1:
            return bool(both)
        entry[1] = bits | 1 << back
        return False

    def newest(self, gid: bytes) -> int | None:
        """The newest sequence number of ``gid`` delivered (None: none yet)."""
        entry = self._by_gid.get(gid)
        return None if entry is None else entry[0]

    def forget(self, gid: bytes) -> None:
        self._by_gid.pop(gid, None)


class _Inbound:
    """One topic's zenoh subscriber; hands checked, decoded messages to the bus.

    A plain topic's samples are taken by the loop itself while it keeps up (:class:`_Puller`);
    a transient-local topic's (zenoh-ext's advanced subscriber) are checked and decoded on zenoh's
    callback thread. Either way (and the iceoryx2 input's, for ``iceoryx2_topics``) a message is
    queued in the inbox of the loop the topic's subscriptions run on, where :meth:`_Inbox.drain`
    injects it.
    """

    def __init__(self, transport: ZenohTransport, topic: str, msg_type: Any, type_hash: str) -> None:
        import zenoh

        self.transport = transport
        self.topic = topic
        self.msg_type = msg_type
        self.type_hash = type_hash
        self.prefix = f"{transport.domain_id}/{topic.strip('/')}/{dds_type(msg_type.__msgtype__)}"
        self.key = f"{self.prefix}/{type_hash}"
        self.key_expr = zenoh.KeyExpr(self.key)
        #: ``key`` declared to the session (once the first subscription declares): zenoh caches the
        #: route of a sample whose key is a declared resource and computes it for every other one,
        #: matching it against every declaration of the session (docs/zenoh.md)
        self._declared: Any = None
        self.subscriptions: list[Subscription[Any]] = []
        self.zsub: Any = None
        self.puller: _Puller | None = None  # a plain subscriber's (None: zenoh-ext's, with a callback)
        self.advanced = False
        self.depth = 0
        self.chunk = MAX_CHUNK
        self.fallback = _Injector(transport._owner, msg_type, topic, _FALLBACK_QOS, "<zenoh>", hidden=True, fresh=True)
        self._injector: _Injector | None = None  # the injector of the last sample's GID
        self._gid = b""
        self.inbox: _Inbox | None = None  # the loop's that delivers it; None: the main loop's
        self.decode = decoder(msg_type, view=True)  # received messages: arrays are read-only views
        self.iox: Any = None  # the iceoryx2 input (iceoryx2_topics): messages may arrive both ways
        self._iox_token: Any = None
        self._delivered = Delivered()
        #: a plain topic's samples missing from their publishers' sequence numbers, as rmw_zenoh
        #: counts them: ``lost`` by the decoding side, ``_lost_told`` by the loop that reports them
        self._last_seq: dict[bytes, int] = {}
        self.lost = 0
        self._lost_told = 0
        self._history_asked: set[str] = set()  # sessions whose publishers' caches this inbound queried
        self._queriers: dict[str, tuple[Any, Any]] = {}  # session -> (querier, matching listener) still asking

    def add(self, sub: Any) -> None:
        self.subscriptions.append(sub)
        self._rechunk()

    def remove(self, sub: Any) -> None:
        self.subscriptions.remove(sub)
        self._rechunk()

    def _rechunk(self) -> None:
        depths = [s.qos.depth for s in self.subscriptions if s.qos.history is HistoryPolicy.KEEP_LAST]
        self.chunk = max(1, min([MAX_CHUNK, *depths]))
        self.inbox = self.transport._inbox_for(delivery_loop(self.subscriptions, self.transport._loop))

    def declare(self, qos: QoSProfile) -> None:
        import zenoh
        import zenoh.ext

        session = self.transport._session
        want_history = qos.durability is DurabilityPolicy.TRANSIENT_LOCAL
        depth = qos.depth if qos.history is HistoryPolicy.KEEP_LAST else 1000
        if self.zsub is not None and (self.advanced or not want_history) and depth <= self.depth:
            return
        old, old_puller = self.zsub, self.puller
        if self._declared is None:
            self._declared = session.declare_keyexpr(self.key)
        self.depth = max(depth, self.depth)
        self._delivered.window = max(self._delivered.window, self.depth)
        key = self.prefix + "/*"  # any hash: a mismatch is reported, not silently missed
        if want_history or self.advanced:
            reliable = qos.reliability is ReliabilityPolicy.RELIABLE
            self.advanced = True  # (before: its history may arrive while it is being declared, numbered)
            self.zsub = zenoh.ext.declare_advanced_subscriber(
                session,
                key,
                self._on_sample,
                allowed_origin=zenoh.Locality.REMOTE,
                history=zenoh.ext.HistoryConfig(detect_late_publishers=True, max_samples=self.depth),
                recovery=zenoh.ext.RecoveryConfig(periodic_queries=None, heartbeat=True) if reliable else None,
                subscriber_detection=True,
            )
            self.puller = None
            self._history_asked.clear()
            self.transport._ask_histories(self)  # (a session asked before: its new querier replaces the old)
        else:
            self.zsub = session.declare_subscriber(
                key, zenoh.handlers.RingChannel(PULL_CAPACITY), allowed_origin=zenoh.Locality.REMOTE
            )
            self.puller = _Puller(self, self.zsub)
        if old_puller is not None:
            old_puller.close()
        elif old is not None:
            old.undeclare()

    def _on_sample(self, sample: Any) -> None:
        """A transient-local topic's zenoh callback (a plain topic's samples go through its
        :class:`_Puller`, which decodes before waking too).

        On a zenoh thread: check and decode the sample, queue it in the inbox of the loop the
        topic's subscriptions run on, and wake that loop unless a drain is due already (one
        ``call_soon_threadsafe`` per batch of samples that arrive together).

        The loop is woken after the decoding, not before it: woken first, it competed with this
        thread for the GIL during the decoding; the wake-up then cost a Twist 12-17 us and an image
        ~50 us on this 2-CPU VM, against 2-7 us after it (docs/zenoh.md)."""
        decoded = self._decode(sample)
        if decoded is not None:
            (self.inbox or self.transport._inbox).put(self, decoded)

    def _decode(self, sample: Any) -> tuple[bytes, Any] | None:
        """Check a sample (key, attachment, CDR) and decode it: ``(gid, message)``, or None when dropped."""
        transport = self.transport
        key_expr = sample.key_expr
        try:
            if key_expr != self.key_expr:  # (compared as zenoh key expressions: no string made)
                found_hash = str(key_expr)[len(self.prefix) + 1 :]
                raise WireError(
                    f"type hash on {self.topic}: expected {self.type_hash} for {self.msg_type.__msgtype__}, "
                    f"found {found_hash or 'none'}; the two sides use different definitions"
                )
            raw = sample.attachment
            att = None if raw is None else raw.to_bytes()
            if att is None or len(att) != ATTACHMENT_SIZE or att[16] != 16:
                attachment_gid(att)  # raises the WireError that says what is wrong
            gid = att[17:]
            payload = sample.payload
            data = payload.to_bytes()
            msg = self.decode(data)  # arrays: read-only views into the bytes
            if len(data) >= SHM_MIN_CHECK and payload.as_shm() is not None:
                transport._received_shm += 1
        except Exception as err:  # noqa: BLE001 - nothing from the network may escape
            transport._drop_sample(str(key_expr), err)
            return None
        transport._received += 1
        seq = _SEQ.unpack_from(att)[0]
        if self.iox is not None or self.advanced:
            return gid, msg, seq
        last = self._last_seq.get(gid)
        if last is None or seq > last:  # (a lower one, a copy that came twice as the subscriber was
            self._last_seq[gid] = seq  # declared again, changes nothing)
            if last is not None and seq > last + 1:
                self.lost += seq - last - 1
        return gid, msg


    def _inject(self, gid: bytes, msg: Any, seq: int | None = None, iceoryx2: bool = False) -> None:
        """On the inbox's loop: publish a received message into the bus as its remote publisher.
        ``seq``: its sequence number, when it may arrive two ways (over iceoryx2 and zenoh; on a
        transient-local topic, as history from zenoh-ext and from the transport's own query)."""
        if seq is not None:
            if self.advanced:  # a transient-local topic keeps its last ``depth``: never one older
                newest = self._delivered.newest(gid)
                if newest is not None and newest - seq >= self.depth:
                    return
            delivered = self._delivered
            if delivered.seen(gid, seq, iceoryx2 or self.advanced, count=not self.advanced):
                return
            if delivered.lost:  # (an iceoryx2 topic's: a plain one's are counted as they are decoded)
                self.lost += delivered.lost
                delivered.lost = 0
        injector = self._injector
        if gid != self._gid or injector is None or injector.destroyed:
            injector = self.transport._by_gid.get(gid)
            if injector is None or injector.topic_name != self.topic or injector.msg_type is not self.msg_type:
                injector = self.fallback  # not remembered: the publisher's own injector may arrive later
            else:
                self._gid, self._injector = gid, injector
        if injector.destroyed:
            return
        if self.lost != self._lost_told:
            self._report_lost()
        try:
            injector.publish(msg)  # (not to the outbound taps: see _Injector._set_targets)
        except Exception as err:  # noqa: BLE001
            self.transport._warn("inject", f"could not deliver a message on {self.topic}: {err}")

    def _report_lost(self) -> None:
        """On the loop: say how many samples the topic lost since the last report, and count them
        on its subscriptions' ``message_lost`` events (as rmw_zenoh does)."""
        n = self.lost - self._lost_told
        self._lost_told += n
        behind = f"{PULL_CAPACITY} samples"
        if self.iox is not None:
            from ._iceoryx2 import BUFFER_SIZE

            behind = f"{PULL_CAPACITY} samples over zenoh or {BUFFER_SIZE} over iceoryx2"
        self.transport._warn(
            "lost",
            f"{n} samples on {self.topic} never arrived (gaps in their publishers' sequence numbers): the "
            f"publisher or the network dropped them, or this process fell more than {behind} behind",
            count=n,
        )
        for sub in self.subscriptions:
            lost = getattr(sub, "_lost", None)
            if lost is not None:
                lost._fire(n)

    def _history_answered(self, zid: str, querier: Any, replies: list[tuple[bytes, Any, int]]) -> None:
        """On the loop: session ``zid``'s caches answered ``querier``'s query; done with it."""
        if querier is not None and self._queriers.get(zid) is querier:
            _undeclare(self._queriers.pop(zid))
        self._late_history(replies)

    def _late_history(self, replies: list[tuple[bytes, Any, int]]) -> None:
        """On the loop: the history a remote session's publisher caches answered with (transient
        local), delivered unless delivered already. One older than the ``depth`` newest of its
        publisher delivered so far is left out: a subscription that keeps the last ``depth``
        messages would not hold it (a depth-1 latched topic never goes back to an older message)."""
        if self.zsub is None:
            return
        for gid, msg, seq in sorted(replies, key=lambda r: (r[0], r[2])):
            self._inject(gid, msg, seq)

    def close(self) -> None:
        for querier in self._queriers.values():
            _undeclare(querier)
        self._queriers.clear()
        if self._iox_token is not None:
            self._iox_token.undeclare()
            self._iox_token = None
        if self.iox is not None:
            self.iox.close()
            self.iox = None
        if self.puller is not None:
            self.puller.close()
            self.puller = None
        elif self.zsub is not None:
            self.zsub.undeclare()
        self.zsub = None
        if self._declared is not None:
            self.transport._session.undeclare(self._declared)
            self._declared = None


class _Puller:
    """A plain topic's zenoh subscriber whose samples the loop takes itself while it keeps up.

    zenoh queues the topic's samples in a channel. The puller's thread waits for one, checks and
    decodes it and queues it in the inbox, waking the loop (as a zenoh callback did); the loop,
    having delivered it, takes the samples that came meanwhile straight from the channel
    (:meth:`pull`, the topic's chunk at most per drain) until it is dry, then hands back and the
    thread waits for the next one. In a burst the loop so takes every sample with no thread of
    ours in between: with a zenoh callback thread, the two took turns at the GIL for every sample
    (14.8 us of Python-thread CPU per Twist in the bench's burst, against 7.8 us now; docs/zenoh.md).

    A loop that took none for ``STALL_SEC`` twice in a row (a callback blocking it) no longer
    pulls: the thread takes each sample and queues it (``pushing``), as a callback did, so the
    samples are checked and decoded while the loop is held up, and a loop that stays stalled loses
    the oldest past ``BACKLOG_LIMIT`` and says so. (zenoh's receiving thread never waits on the
    topic either way: its channel is a ring, ``PULL_CAPACITY``.)
    The thread hands back to the loop once the inbox is empty again. One of the two takes samples
    at a time, and a taken sample is delivered before any taken after it: each topic's messages
    keep their order.
    """

    def __init__(self, inbound: _Inbound, zsub: Any) -> None:
        self.inbound = inbound
        self.zsub = zsub
        self.channel = zsub.handler
        self.lock = threading.Lock()
        self.pulling = False  # the loop takes the samples (only it, while this is set)
        self.pushing = False  # the thread takes them and queues them (the loop stalled)
        #: held by the thread while the loop pulls; the loop releases it when it finds the channel
        #: dry (a lock as a semaphore: its timed wait is one C call, an Event's a Condition's Python)
        self.gate = threading.Lock()
        self.gate.acquire()
        self.taken = 0  # samples the loop took so far: its progress, for the stall watch
        self.closed = False
        self.thread = threading.Thread(target=self._run, name=f"aiorobot-zenoh {inbound.topic}", daemon=True)
        self.thread.start()

    def _run(self) -> None:
        """The puller's thread: wait for a sample; queue it; watch the loop take the rest."""
        inbound, channel = self.inbound, self.channel
        while not self.closed:
            try:
                sample = channel.recv()
            except Exception:  # noqa: BLE001 - the subscriber was undeclared: its channel closed
                return
            decoded = inbound._decode(sample)
            if decoded is None or self.closed:
                continue
            inbox = inbound.inbox or inbound.transport._inbox
            if self.pushing and inbox.pending:  # the loop has not caught up: queue it, as a callback did
                inbox.put(inbound, decoded)
                continue
            with self.lock:
                self.pushing = False
                self.pulling = True
            inbox.put(inbound, decoded)  # the loop delivers it, then takes the rest (pull)
            self._watch()

    def _watch(self) -> None:
        """Until the loop hands back; stop its pulling when it takes nothing for 2 x ``STALL_SEC``."""
        seen, idle = self.taken, 0
        while not self.gate.acquire(timeout=STALL_SEC):
            with self.lock:
                if self.closed:
                    return
                if not self.pulling:  # handed back since the wait timed out: the gate is open
                    self.gate.acquire()  # (at once)
                    return
                if self.taken != seen:
                    seen, idle = self.taken, 0
                    continue
                idle += 1
                if idle >= 2:  # stalled: the thread takes the samples from now on
                    self.pulling, self.pushing = False, True
                    return

    def pull(self, batch: EagerBatch, room: int) -> int:
        """On the loop, after delivering one of the topic's messages: deliver up to ``room`` more
        samples waiting in the channel; how many it took. Hands back when the channel is dry."""
        inbound, channel, lock = self.inbound, self.channel, self.lock
        got = 0
        while got < room:
            with lock:
                if not self.pulling:
                    return got  # the thread took over meanwhile
                try:
                    sample = channel.try_recv()
                except Exception:  # noqa: BLE001 - undeclared: closed
                    sample = None
                if sample is None:
                    self.pulling = False
                    self.gate.release()  # the thread waits for the next sample
                    return got
                self.taken += 1
            got += 1
            decoded = inbound._decode(sample)
            if decoded is not None:
                inbound._inject(*decoded)
                if batch.ready:
                    batch.run()
        return got

    def close(self) -> None:
        with self.lock:
            self.closed = True
            if self.pulling:  # (the thread waits at the gate)
                self.pulling = False
                self.gate.release()
        self.zsub.undeclare()  # (the thread's wait on the channel ends)
        if self.thread is not threading.current_thread():
            self.thread.join(timeout=5.0)


def delivery_loop(subscriptions: list[Any], main: asyncio.AbstractEventLoop | None) -> asyncio.AbstractEventLoop | None:
    """The loop a topic's received messages are injected on: that of a subscription off the main
    loop when there is one (the priority loop: a blocked main loop must not hold its inputs back;
    main-loop subscriptions of the topic then get them by a post), else ``main``."""
    for sub in subscriptions:
        node = getattr(sub, "node", None)
        loop = node._loop if node is not None else None  # (lowlevel.node_loop; importing lowlevel loads launch)
        if loop is not None and loop is not main:
            return loop
    return main


class _Inbox:
    """Received messages on their way to one loop: ``(inbound, (gid, message))`` in arrival order
    (``(inbound, None)``: take more of a pulling topic's samples), injected there by
    :meth:`drain`, one drain due at a time.

    Each loop has its own, so that a topic whose subscriptions run on the priority loop is
    delivered by that loop even while a main-loop callback blocks."""

    def __init__(self, transport: ZenohTransport, loop: asyncio.AbstractEventLoop | None) -> None:
        self.transport = transport
        self._fixed_loop = loop  # None: the transport's (main) loop, known once it opens
        self.loop_name = "main" if loop is None else "priority"
        self.pending: deque[tuple[_Inbound, Any]] = deque()
        self.armed = False  # a drain is due on the loop
        self._arming = threading.Lock()

    @property
    def loop(self) -> asyncio.AbstractEventLoop | None:
        return self._fixed_loop or self.transport._loop

    def put(self, inbound: _Inbound, decoded: Any) -> None:
        """On a zenoh thread: queue a decoded message; wake the loop if no drain is due."""
        pending = self.pending
        if len(pending) >= BACKLOG_LIMIT:
            lost, _ = pending.popleft()
            self.transport._warn(
                "backlog", f"dropped the oldest sample on {lost.topic}: {BACKLOG_LIMIT} were waiting for the {self.loop_name} loop"
            )
        pending.append((inbound, decoded))
        if not self.armed:  # no drain due: wake the loop
            self.arm()

    def arm(self) -> None:
        with self._arming:
            if self.armed:
                return
            self.armed = True
        loop = self.loop
        if loop is not None:
            post(loop, self.drain)

    def drain(self) -> None:
        """On the inbox's loop: inject queued messages in arrival order, and after a pulling
        topic's message the samples waiting in its channel (:class:`_Puller`), at most ``chunk``
        of one topic (its smallest subscription depth) before the dispatchers run, and
        ``MAX_DRAIN`` in all; then the next drain. One drain is due at a time; messages that pile
        up while the process is descheduled so never fill a subscription queue past its depth, and
        each topic keeps its order (topics take turns by chunks). Each message is delivered
        eagerly (``EagerBatch``): an idle subscription's plain-function callback runs here, not one
        loop iteration later in its dispatcher."""
        pending = self.pending
        taken: dict[_Inbound, int] = {}
        budget = MAX_DRAIN
        try:
            with EagerBatch() as batch:
                while budget > 0:
                    try:
                        inbound, decoded = item = pending.popleft()  # (zenoh's thread may pop the oldest too)
                    except IndexError:
                        break
                    n = taken.get(inbound, 0)
                    if n >= inbound.chunk:
                        pending.appendleft(item)  # the topic's dispatchers run first
                        break
                    if inbound.zsub is None:
                        continue  # the topic's last subscription left meanwhile
                    if decoded is not None:  # (None: go on taking a pulling topic's samples)
                        n += 1
                        budget -= 1
                        inbound._inject(*decoded)
                        if batch.ready:
                            batch.run()
                    puller = inbound.puller
                    if puller is not None and puller.pulling:
                        room = min(inbound.chunk - n, budget)
                        got = puller.pull(batch, room)
                        n += got
                        budget -= got
                        if got == room and puller.pulling:
                            pending.append((inbound, None))  # more may be waiting: after the other topics
                    taken[inbound] = n
        finally:  # (also when a callback run here raises KeyboardInterrupt: the rest is not stranded)
            self._next()

    def _next(self) -> None:
        """After a drain: the next one, when messages are left or came in meanwhile."""
        pending, loop = self.pending, self.loop
        if not pending or loop is None or loop.is_closed():
            with self._arming:
                self.armed = False
                if not pending or loop is None or loop.is_closed():
                    return
                self.armed = True  # a sample came in between: it would wait for the next one
        loop.call_soon(self.drain)


class ZenohTransport(Transport):
    """Joins every aiorobot process (and ROS 2 node on rmw_zenoh) on the same zenoh network and domain.

    Parameters
    ----------
    domain_id
        ``ROS_DOMAIN_ID``: the first chunk of every key.
    config_file
        A zenoh JSON5 config file used as is (routers, TLS/mTLS, access control).
        Without one: peer mode, listen on ``tcp/127.0.0.1:0``, connect to a router
        on ``tcp/127.0.0.1:7447``, multicast scouting off (rmw_zenoh's defaults, on
        loopback). ``ZENOH_SESSION_CONFIG_URI`` names a file too, and
        ``ZENOH_CONFIG_OVERRIDE`` (``key=value;key=value``) applies last, as in rmw_zenoh.
    connect, listen
        Endpoints replacing the defaults.
    allow_plain
        Plain (non-TLS) endpoints allowed in a config that enables TLS or access control
        (``AIOROBOT_ZENOH_ALLOW_PLAIN`` adds more); any other plain listener or connect
        endpoint there, zenoh's peer default ``tcp/[::]:0`` included, refuses to open
        (:class:`~aiorobot.transport.ZenohConfigError`). See docs/security.md.
    shared_memory
        ``True``/``False`` sets zenoh's ``transport/shared_memory/enabled`` (over a config
        file too); ``None``: on with the default config, as the file says with one. When on,
        a message whose CDR is ``shm_threshold`` bytes or more (``ZENOH_SHM_MESSAGE_SIZE_THRESHOLD``,
        2 KiB) is put from a shared-memory pool (``ZENOH_SHM_ALLOC_SIZE``, 48 MiB), as
        rmw_zenoh does: a peer on this host maps it instead of receiving it over the socket.
    iceoryx2_topics
        Topics whose large messages (``shm_threshold`` bytes of CDR or more) go over iceoryx2's
        shared memory between aiorobot processes on this host, serialised straight into a loaned
        sample (one copy of an image end to end, against three over zenoh); ``"*"`` is every
        topic whose type carries an unbounded array of numbers (images, point clouds, scans).
        ``AIOROBOT_ICEORYX2_TOPICS=/a,/b`` (or ``*``) when this is None. Discovery, the graph,
        small messages and everything else stay on zenoh. A subscribing process announces its
        iceoryx2 input over zenoh; a publisher whose remote subscribers are all served that way
        sends large messages over iceoryx2 only, and to any other (another host, an rmw_zenoh
        node, a process without the topic listed) over zenoh as before; a message that arrives
        both ways is delivered once. Needs ``iceoryx2`` (``pip install aiorobot[iceoryx2]``).
        See docs/zenoh.md.
    """

    name = "zenoh"

    def __init__(
        self,
        *,
        domain_id: int = 0,
        config_file: str | None = None,
        connect: list[str] | None = None,
        listen: list[str] | None = None,
        shared_memory: bool | None = None,
        allow_plain: list[str] | tuple[str, ...] = (),
        iceoryx2_topics: list[str] | tuple[str, ...] | None = None,
    ) -> None:
        super().__init__(domain_id=domain_id)
        self.allow_plain = tuple(allow_plain)
        if iceoryx2_topics is None:
            iceoryx2_topics = os.environ.get("AIOROBOT_ICEORYX2_TOPICS", "").split(",")
        self.iceoryx2_topics = frozenset(
            t.strip() if t.strip() == "*" else "/" + t.strip().strip("/") for t in iceoryx2_topics if t.strip().strip("/")
        )
        self._iox: Any = None  # the iceoryx2 node (Iceoryx2Host) while open, when iceoryx2_topics names any
        self._iox_sub: Any = None  # the liveliness subscriber of other processes' iceoryx2 inputs
        self._iox_inputs: dict[tuple[str, str], dict[str, int]] = {}  # (topic, hash) -> session -> its iceoryx2 node
        self._sub_zids: dict[tuple[str, str], Counter[str]] = {}  # (topic, hash) -> remote subscriptions per session
        self._own_gids: set[bytes] = set()
        self._sent_iox = 0
        self._received_iox = 0
        self._connect_failures = 0
        self.config_file = config_file
        self.connect = connect
        self.listen = listen
        self.shared_memory = shared_memory
        self._session: Any = None
        self._zid = ""
        self._loop: asyncio.AbstractEventLoop | None = None
        self._owner: _Owner = None  # type: ignore[assignment]
        self._lock = threading.RLock()
        self._ids = itertools.count(1)
        self._nodes: dict[int, _LocalNode] = {}
        self._tokens: dict[int, Any] = {}  # id(endpoint) -> liveliness token
        self._outbound: dict[tuple[str, str], _Outbound] = {}
        self._inbound: dict[tuple[str, str], _Inbound] = {}
        self._queryables: dict[int, Any] = {}
        self._remote: dict[str, Any] = {}  # token -> what it added to the bus
        self._describing: dict[str, Any] = {}  # token -> its TokenInfo, while its type's description is asked for
        self._descriptions: dict[tuple[str, str], str] = {}  # (type, hash) -> "asked" | "known" | "failed" | "unanswered"
        self._undescribed: dict[str, list[Any]] = {}  # node -> TokenInfos asked again once it serves get_type_description
        self._describers: set[str] = set()  # nodes whose get_type_description service was seen
        self._asks: Counter[tuple[str, str]] = Counter()  # queries sent per (type, hash)
        self._remote_nodes: dict[str, NodeInfo] = {}
        self._by_gid: dict[bytes, _Injector] = {}
        self._liveliness_sub: Any = None
        self._sent = 0
        self._received = 0
        self._drops: Counter[str] = Counter()
        self._last_warning: dict[str, float] = {}
        self._hashes: dict[Any, str] = {}
        self._shm: Any = None  # zenoh.shm.ShmProvider when the session has shared memory enabled
        self._shm_threshold = SHM_THRESHOLD
        self._shm_from = float("inf")  # the threshold while a pool is open, else never
        self._sent_shm = 0
        self._received_shm = 0
        self._drops_shm_full = 0  # sends that fell back to the network because the pool was full
        self._shm_lock = threading.Lock()
        # received messages on their way to the main loop, and to the other loops (the priority
        # loop) their topics' subscriptions run on
        self._inbox = _Inbox(self, None)
        self._inboxes: dict[asyncio.AbstractEventLoop, _Inbox] = {}

    def __repr__(self) -> str:
        state = f"zid={self._zid}" if self._session is not None else "closed"
        return f"<ZenohTransport domain_id={self.domain_id} {state} remote_nodes={len(self._remote_nodes)}>"

    # -- session --------------------------------------------------------------------

    def _config(self) -> tuple[Any, SessionPlan]:
        return build_session_config(
            config_file=self.config_file, connect=self.connect, listen=self.listen,
            shared_memory=self.shared_memory, allow_plain=self.allow_plain,
        )

    async def open(self, bus: Bus) -> None:
        import zenoh

        cfg, plan = self._config()  # a bad config or certificate path: ZenohConfigError, nothing opened
        if self.iceoryx2_topics:
            from ._iceoryx2 import unavailable

            why = unavailable()
            if why is not None:
                raise ZenohConfigError(
                    "ZenohTransport(iceoryx2_topics=) / AIOROBOT_ICEORYX2_TOPICS", None,
                    f"{', '.join(sorted(self.iceoryx2_topics))} over iceoryx2: expected the iceoryx2 package, found none ({why})",
                )
        await super().open(bus)
        self._loop = asyncio.get_running_loop()
        self._owner = _Owner(self._loop, threading.get_ident(), "<zenoh>")
        try:
            self._session = await asyncio.to_thread(zenoh.open, cfg)
        except Exception as err:  # noqa: BLE001 - zenoh raises ZError: say what was refused, and where
            raise ZenohSessionError(await asyncio.to_thread(_refusal, plan, err)) from None
        self._zid = str(self._session.zid())
        self._open_shm(cfg)
        bus.services.listener = self  # type: ignore[attr-defined]
        self._liveliness_sub = self._session.liveliness().declare_subscriber(
            f"@ros2_lv/{self.domain_id}/**", self._on_token, history=True
        )
        if self.iceoryx2_topics:
            from ._iceoryx2 import TOKEN_PREFIX, Iceoryx2Host

            try:
                self._iox = Iceoryx2Host()
            except Exception as err:  # noqa: BLE001 - no shared memory here: everything over zenoh, said once
                _log.warning(
                    f"iceoryx2_topics: iceoryx2 could not open a node ({type(err).__name__}: {err}); "
                    f"{', '.join(sorted(self.iceoryx2_topics))} go over zenoh"
                )
            else:
                self._iox_sub = self._session.liveliness().declare_subscriber(
                    f"{TOKEN_PREFIX}/{self.domain_id}/**", self._on_iox_token, history=True
                )
        await asyncio.to_thread(self._report_unlinked, plan)

    def _peers_chosen(self, plan: SessionPlan) -> bool:
        """The caller or the file chose endpoints beyond the default router: peer-to-peer links."""
        if plan.source == DEFAULT_SOURCE:
            return self.listen is not None or (self.connect is not None and list(self.connect) != [DEFAULT_CONNECT])
        return not plan.listen_is_default or list(plan.connect) != [DEFAULT_CONNECT]

    def _report_unlinked(self, plan: SessionPlan) -> None:
        """A peer whose connect endpoints did not link opens anyway and would run on alone, silently:
        say which and why (one warning each, counted in ``statistics().connect_failures``)."""
        unlinked = _unlinked(self._session, plan.connect)
        if not unlinked:
            return
        reasons = {endpoint: why_unreachable(endpoint, plan.tls) for endpoint in unlinked}
        unlinked = _unlinked(self._session, tuple(unlinked))  # a link that came up while probing is no failure
        self._connect_failures += len(unlinked)
        for endpoint in unlinked:
            why = reasons[endpoint]
            if endpoint == DEFAULT_CONNECT and why.startswith(NOTHING_LISTENS):
                if self._peers_chosen(plan) or _skip_router_check():
                    continue  # peer-to-peer by choice: the session does not need the router
                if not _router_warned.is_set():  # once a process, as rmw_zenoh's router check
                    _router_warned.set()
                    _log.warning(
                        f"no zenoh router at {DEFAULT_CONNECT}; other processes will not be found: "
                        "start `aiorobot router`"
                    )
                continue
            _log.warning(
                f"zenoh session ({plan.mode} mode, {plan.source}) could not connect to {endpoint}: {why}; "
                "it runs without it and keeps retrying"
            )

    async def close(self) -> None:
        session = self._session
        if session is None:
            return
        if self._liveliness_sub is not None:
            self._liveliness_sub.undeclare()
        if self._iox_sub is not None:
            self._iox_sub.undeclare()
            self._iox_sub = None
        bus = self.bus
        with self._lock:
            for token in list(self._remote):
                self._forget(token)
            for out in self._outbound.values():
                if bus is not None:
                    bus.remove(out.tap)
                out.close()
            for inb in self._inbound.values():
                if bus is not None:
                    bus.remove(inb.fallback)
                inb.close()
            for q in self._queryables.values():
                q.undeclare()
            for token in [*self._tokens.values(), *(n.token for n in self._nodes.values())]:
                token.undeclare()
            self._outbound.clear()
            self._inbound.clear()
            self._inbox.pending.clear()
            self._inboxes.clear()
            self._queryables.clear()
            self._tokens.clear()
            self._nodes.clear()
            self._iox_inputs.clear()
            self._sub_zids.clear()
            if self._iox is not None:
                self._iox.close()
                self._iox = None
        if bus is not None and getattr(bus.services, "listener", None) is self:
            bus.services.listener = None  # type: ignore[attr-defined]
        self._session = None
        await asyncio.to_thread(session.close)
        await super().close()

    @property
    def zid(self) -> str:
        return self._zid

    def statistics(self) -> TransportStatistics:
        return TransportStatistics(
            self._sent, self._received, sum(self._drops.values()), dict(self._drops), len(self._remote_nodes),
            self._sent_shm, self._received_shm, self._connect_failures, self._sent_iox, self._received_iox,
        )

    def remote_nodes(self) -> tuple[NodeInfo, ...]:
        return tuple(self._remote_nodes.values())

    # -- shared memory --------------------------------------------------------------------

    def _open_shm(self, cfg: Any) -> None:
        """A shared-memory pool when the config enables it (rmw_zenoh's ``ZENOH_SHM_*`` settings)."""
        try:
            enabled = json.loads(cfg.get_json("transport/shared_memory/enabled"))
        except Exception:  # noqa: BLE001 - a config without the key: zenoh's default (off)
            enabled = False
        if enabled is not True:
            return
        size = _env_bytes("ZENOH_SHM_ALLOC_SIZE", SHM_ALLOC_SIZE)
        self.shm_threshold = _env_bytes("ZENOH_SHM_MESSAGE_SIZE_THRESHOLD", SHM_THRESHOLD)
        try:
            from zenoh.shm import ShmProvider

            self._shm = ShmProvider.default_backend(size)
            self._shm_from = self._shm_threshold
        except Exception as err:  # noqa: BLE001 - no /dev/shm, a platform without it: use the network
            _log.warning(f"zenoh shared memory is enabled but a {size}-byte pool could not be made ({err}); large messages go over the network")

    @property
    def shm_threshold(self) -> int:
        """Messages of this many bytes or more (CDR) go through shared memory, when it is enabled."""
        return self._shm_threshold

    @shm_threshold.setter
    def shm_threshold(self, value: int) -> None:
        self._shm_threshold = value
        if self._shm is not None:
            self._shm_from = value

    def _payload(self, data: bytes) -> Any:
        """``data`` as zenoh should send it: in a shared-memory buffer when it is large enough."""
        shm = self._shm
        if shm is None or len(data) < self.shm_threshold:
            return data
        from zenoh.shm import GarbageCollect

        try:
            with self._shm_lock:
                buf = shm.alloc(len(data), GarbageCollect())
        except Exception:  # noqa: BLE001 - the pool is full (subscribers still hold buffers): copy
            self._drops_shm_full += 1
            return data
        buf[:] = data
        self._sent_shm += 1
        return buf

    # -- helpers --------------------------------------------------------------------------

    def _warn(self, reason: str, text: str, count: int = 1) -> None:
        self._drops[reason] += count
        now = time.monotonic()
        if now - self._last_warning.get(reason, -1e9) >= WARN_INTERVAL_SEC:
            self._last_warning[reason] = now
            _log.warning(f"{text} ({self._drops[reason]} dropped so far for this reason)")

    def _drop_sample(self, where: str, err: Exception) -> None:
        """Say why a received sample on ``where`` (a key or a topic) was dropped, counted by reason."""
        if isinstance(err, WireError):
            self._warn("wire", f"dropped a sample on {where}: {err}")
        elif isinstance(err, _DeserializationError):
            self._warn("cdr", f"dropped a sample on {where}: malformed CDR: {err}")
        else:
            self._warn("other", f"dropped a sample on {where}: {type(err).__name__}: {err}")

    def _to_loop(self, fn: Any, *args: Any) -> None:
        if self._loop is not None:
            post(self._loop, fn, *args)

    def _inbox_for(self, loop: asyncio.AbstractEventLoop | None) -> _Inbox | None:
        """The inbox of ``loop`` (None: the main loop's)."""
        if loop is None or loop is self._loop:
            return None
        inbox = self._inboxes.get(loop)
        if inbox is None:
            inbox = self._inboxes[loop] = _Inbox(self, loop)
        return inbox

    def _iceoryx2_service(self, topic: str, type_hash: str) -> str:
        """The iceoryx2 service of ``topic`` in this domain (every process on the host derives it)."""
        return f"aiorobot/{self.domain_id}/{topic.strip('/')}/{type_hash}"

    def _iceoryx2_for(self, topic: str, msg_type: Any) -> bool:
        """Whether ``topic``'s large messages take the iceoryx2 path here (``iceoryx2_topics``)."""
        if self._iox is None:
            return False
        if topic in self.iceoryx2_topics:
            return True
        if "*" not in self.iceoryx2_topics:
            return False
        from ._iceoryx2 import carries_arrays

        return carries_arrays(msg_type)

    def _open_iox_input(self, inb: _Inbound) -> None:
        """Receive ``inb``'s topic over iceoryx2 too, and say so to the other processes (the
        token after the subscriber: a publisher that sees it finds the subscriber connected)."""
        from ._iceoryx2 import Iceoryx2Input, token_key

        try:
            inb.iox = Iceoryx2Input(self._iox, inb, self._iceoryx2_service(inb.topic, inb.type_hash))
        except Exception as err:  # noqa: BLE001 - the service is full, or made by another version
            self._iox_refused(inb.topic, "receive", err)
            return
        inb._iox_token = self._session.liveliness().declare_token(
            token_key(self.domain_id, self._zid, self._iox.node_id, inb.topic, inb.type_hash)
        )
        out = self._outbound.get((inb.topic, inb.msg_type.__msgtype__))
        if out is not None and out.iox is not None:
            out.iox.own = 1

    def _ask_histories(self, inb: _Inbound) -> None:
        """Ask every remote session with a transient-local publisher of ``inb``'s topic for its
        history (zenoh-ext's own query may have gone out before routes to them existed)."""
        for token, entry in list(self._remote.items()):
            if (
                isinstance(entry, _Injector) and entry.topic_name == inb.topic and entry.msg_type is inb.msg_type
                and entry.qos.durability is DurabilityPolicy.TRANSIENT_LOCAL
            ):
                self._ask_history(inb, parse_token(token).zid)

    def _ask_history(self, inb: _Inbound, zid: str) -> None:
        """Query the caches of session ``zid``'s publishers of ``inb``'s topic as soon as a route
        to them exists (a querier's matching status); what they answer is delivered by
        :meth:`_Inbound._late_history` unless delivered already.

        zenoh-ext's advanced subscriber queries every cache when it is declared, and the cache of a
        publisher it discovers later. A session that has just opened may send its first query
        before it knows a route to the publishers (no reply), and a live message delivered before
        the later query's replies makes zenoh-ext drop every older one (its sequenced samples are
        not held while that query is pending): a late joiner then lost the history of a topic whose
        publisher kept publishing (1 trial in 6-8 in a probe). So the transport asks each session
        once itself, and the inbound delivers each (publisher, sequence number) once."""
        import zenoh

        if zid in inb._history_asked or inb.zsub is None:
            return
        inb._history_asked.add(zid)
        replies: list[tuple[bytes, Any, int]] = []
        asked = threading.Event()
        entry: Any = None  # (querier, matching listener), once declared

        def on_reply(reply: Any) -> None:
            sample = reply.ok
            if sample is not None:
                decoded = inb._decode(sample)
                if decoded is not None and len(decoded) == 3:
                    replies.append(decoded)  # type: ignore[arg-type]

        def on_done() -> None:
            loop = inb.inbox.loop if inb.inbox is not None else self._loop
            if loop is not None:
                post(loop, inb._history_answered, zid, entry, replies)

        def ask() -> None:
            if asked.is_set():
                return
            asked.set()
            querier.get(zenoh.handlers.Callback(on_reply, on_done), parameters=f"_max={inb.depth}")

        try:
            # (zenoh-ext 1.10's caches: <key>/@adv/pub/<zid>/<eid>/<meta>, replying on <key>)
            querier = self._session.declare_querier(
                f"{inb.key}/@adv/*/{zid}/**",
                target=zenoh.QueryTarget.ALL,
                consolidation=zenoh.ConsolidationMode.NONE,
                accept_replies=zenoh.ReplyKeyExpr.ANY,
                timeout=DESCRIBE_TIMEOUT_SEC,
            )
            listener = querier.declare_matching_listener(lambda status: status.matching and ask())
            _undeclare(inb._queriers.pop(zid, ()))  # (asked again after a redeclaration: the new one answers)
            entry = inb._queriers[zid] = (querier, listener)
            if querier.matching_status:
                ask()
        except Exception as err:  # noqa: BLE001 - the session is closing: nothing to deliver
            _log.debug(f"history of {inb.topic} from {zid} not asked: {err}")

    def _iox_refused(self, topic: str, what: str, err: Exception) -> None:
        _log.warning(
            f"iceoryx2_topics: cannot {what} {topic} over iceoryx2 ({type(err).__name__}: {err}); "
            "it goes over zenoh in this process"
        )

    def _on_iox_token(self, sample: Any) -> None:
        import zenoh

        self._to_loop(self._iox_token_event, str(sample.key_expr), sample.kind == zenoh.SampleKind.PUT)

    def _iox_token_event(self, token: str, alive: bool) -> None:
        """On the main loop: another process's iceoryx2 input appeared or left."""
        from ._iceoryx2 import parse_token

        if self._iox is None:
            return
        try:
            zid, node_id, topic, type_hash = parse_token(token)
        except ValueError as err:
            self._warn("token", f"ignored an iceoryx2 token: {err}")
            return
        if zid == self._zid:
            return
        key = (topic, type_hash)
        with self._lock:
            inputs = self._iox_inputs.setdefault(key, {})
            if alive:
                inputs[zid] = node_id
            else:
                inputs.pop(zid, None)
                self._iox.cleanup()  # a process killed with SIGKILL leaves its ports counted
            self._refresh_iox(key)

    def _refresh_iox(self, key: tuple[str, str]) -> None:
        """Whether large messages of the topic ``key`` (topic, hash) must go over zenoh too: a
        remote subscription there is not served over iceoryx2, or none is known yet. Served: its
        session announced an input whose iceoryx2 node is attached to the topic's service, which
        proves it maps this host's shared memory (a node elsewhere is not in the list)."""
        topic, type_hash = key
        for (name, _), out in self._outbound.items():
            if name != topic or out.iox is None or out.type_hash != type_hash:
                continue
            zids = self._sub_zids.get(key)
            if not zids:
                out.zenoh_needed = True
                continue
            inputs = self._iox_inputs.get(key, {})
            service = self._iceoryx2_service(topic, type_hash)
            served = [z for z in zids if z in inputs and self._iox.attached(service, inputs[z])]
            needed = len(served) < len(zids)
            if needed != out.zenoh_needed or not out.said:  # say which way large messages go, when it changes
                out.said = True
                if needed:
                    _log.info(
                        f"iceoryx2_topics: large messages on {topic} go over zenoh too: {len(zids) - len(served)} of "
                        f"{len(zids)} subscribing processes are not on this host's iceoryx2 path"
                    )
                else:
                    _log.info(f"iceoryx2_topics: large messages on {topic} go over iceoryx2 alone ({len(zids)} subscribing processes)")
            out.zenoh_needed = needed

    def _hash(self, msg_type: Any) -> str:
        cached = self._hashes.get(msg_type)
        if cached is None:
            from ..msgs import type_hash

            cached = self._hashes[msg_type] = type_hash(msg_type)
        return cached

    def _node(self, node: Node) -> _LocalNode:
        entry = self._nodes.get(id(node))
        if entry is None:
            nid = next(self._ids)
            token = self._session.liveliness().declare_token(
                node_token(self.domain_id, self._zid, nid, "", node.get_namespace() or "/", node.get_name())
            )
            entry = self._nodes[id(node)] = _LocalNode(nid, token)
        return entry

    def _declare_endpoint(self, endpoint: Any, kind: str, name: str, type_name: str, type_hash: str, qos: QoSProfile) -> str:
        node = endpoint.node
        entry = self._node(node)
        token = endpoint_token(
            self.domain_id, self._zid, entry.nid, next(self._ids), kind, "",
            node.get_namespace() or "/", node.get_name(), name, type_name, type_hash, qos,
        )
        self._tokens[id(endpoint)] = self._session.liveliness().declare_token(token)
        return token

    def _drop_token(self, endpoint: Any) -> None:
        token = self._tokens.pop(id(endpoint), None)
        if token is not None:
            token.undeclare()

    # -- nodes ---------------------------------------------------------------------------

    def node_added(self, node: Node) -> None:
        if self._session is None:
            return
        with self._lock:
            self._node(node)

    def node_removed(self, node: Node) -> None:
        with self._lock:
            entry = self._nodes.pop(id(node), None)
            if entry is not None and self._session is not None:
                entry.token.undeclare()

    # -- local endpoints ------------------------------------------------------------------

    def endpoint_added(self, endpoint: Any) -> None:
        if self._session is None or isinstance(endpoint, _Injector) or _own_tap(endpoint):
            return
        with self._lock:
            if isinstance(endpoint, Publisher):
                self._add_publisher(endpoint)
            elif isinstance(endpoint, (Subscription, Tap)):  # a Tap here is a recorder's or a bridge's
                self._add_subscription(endpoint)
            elif isinstance(endpoint, Service):
                self._add_service(endpoint)
            elif isinstance(endpoint, Client):
                self._declare_endpoint(
                    endpoint, "SC", endpoint.srv_name, endpoint.type_name, self._hash(endpoint.srv_type), QoSProfile()
                )

    def endpoint_removed(self, endpoint: Any) -> None:
        if self._session is None or isinstance(endpoint, _Injector) or _own_tap(endpoint):
            return
        with self._lock:
            self._drop_token(endpoint)
            if isinstance(endpoint, Publisher):
                out = self._outbound.get((endpoint.topic_name, endpoint.type_name))
                if out is not None and endpoint in out.publishers:
                    out.publishers.remove(endpoint)
                    if not out.publishers:
                        del self._outbound[(out.topic, endpoint.type_name)]
                        if self.bus is not None:
                            self.bus.remove(out.tap)
                        out.close()
            elif isinstance(endpoint, (Subscription, Tap)):
                inb = self._inbound.get((endpoint.topic_name, endpoint.type_name))
                if inb is not None and endpoint in inb.subscriptions:
                    inb.remove(endpoint)
                    if not inb.subscriptions:
                        del self._inbound[(inb.topic, endpoint.type_name)]
                        if self.bus is not None:
                            self.bus.remove(inb.fallback)
                        inb.close()
                        out = self._outbound.get((inb.topic, endpoint.type_name))
                        if out is not None and out.iox is not None:
                            out.iox.own = 0
            elif isinstance(endpoint, Service):
                q = self._queryables.pop(id(endpoint), None)
                if q is not None:
                    q.undeclare()

    def _add_publisher(self, pub: Publisher[Any]) -> None:
        type_hash = self._hash(pub.msg_type)
        token = self._declare_endpoint(pub, "MP", pub.topic_name, pub.type_name, type_hash, pub.qos)
        key = (pub.topic_name, pub.type_name)
        out = self._outbound.get(key)
        new = out is None
        if out is None:
            out = self._outbound[key] = _Outbound(self, pub.topic_name, pub.msg_type, type_hash)
            out.set_gid(gid_of(token))
        out.declare(pub.qos)
        out.publishers.append(pub)
        if new and self.bus is not None:
            self.bus.add_subscription(out.tap)
        if out.iox is None and not out.advanced and self._iceoryx2_for(pub.topic_name, pub.msg_type):
            # (an advanced publisher's cache must get every message over zenoh: it stays there)
            from ._iceoryx2 import Iceoryx2Sender

            try:
                out.iox = Iceoryx2Sender(self._iox, out, self._iceoryx2_service(pub.topic_name, type_hash))
            except Exception as err:  # noqa: BLE001 - the service is full, or made by another version
                self._iox_refused(pub.topic_name, "publish", err)
                return
            inb = self._inbound.get(key)
            out.iox.own = int(inb is not None and inb.iox is not None)
            self._refresh_iox((pub.topic_name, type_hash))
        elif out.iox is not None and out.advanced:
            out.iox.close()
            out.iox = None

    def _add_subscription(self, sub: Subscription[Any]) -> None:
        type_hash = self._hash(sub.msg_type)
        key = (sub.topic_name, sub.type_name)
        inb = self._inbound.get(key)
        new = inb is None
        if inb is None:
            inb = self._inbound[key] = _Inbound(self, sub.topic_name, sub.msg_type, type_hash)
        inb.add(sub)
        if new and self.bus is not None:
            self.bus.add_publisher(inb.fallback)
        inb.declare(sub.qos)
        if new and self._iceoryx2_for(sub.topic_name, sub.msg_type):
            self._open_iox_input(inb)
        # The zenoh subscriber first, then the liveliness token (as rmw_zenoh): a publisher that sees the
        # token, and so counts the subscription as matched, finds the route to it already declared.
        if sub.node is not None:  # the runtime's /clock tap has no node: it receives without a graph entry
            self._declare_endpoint(sub, "MS", sub.topic_name, sub.type_name, type_hash, sub.qos)

    # -- services --------------------------------------------------------------------------

    def _add_service(self, service: Service) -> None:
        import zenoh

        type_hash = self._hash(service.srv_type)
        self._declare_endpoint(service, "SS", service.srv_name, service.type_name, type_hash, QoSProfile())
        key = data_key(self.domain_id, service.srv_name, service.type_name, type_hash)

        def on_query(query: Any) -> None:
            self._on_query(service, query)

        self._queryables[id(service)] = self._session.declare_queryable(
            key, on_query, complete=True, allowed_origin=zenoh.Locality.REMOTE
        )

    def _on_query(self, service: Service, query: Any) -> None:
        """On a zenoh thread: decode a request, then serve it like a local call."""
        from ..msgs import DeserializationError, deserialize

        key = str(query.key_expr)
        try:
            raw = query.attachment
            attachment = unpack_attachment(None if raw is None else raw.to_bytes())
            payload = query.payload
            request = deserialize(b"" if payload is None else payload.to_bytes(), service.srv_type.Request)
        except (WireError, DeserializationError) as err:
            self._warn("query", f"dropped a request on {key}: {err}")
            query.drop()
            return
        self._received += 1
        self._to_loop(self._serve, service, query, attachment, request)

    def _serve(self, service: Service, query: Any, attachment: Any, request: Any) -> None:
        loop = asyncio.get_running_loop()
        future: asyncio.Future[Any] = loop.create_future()

        def done(fut: asyncio.Future[Any]) -> None:
            from ..msgs import serialize

            try:
                if fut.cancelled():
                    query.reply_err(f"service {service.srv_name} was cancelled".encode())
                elif fut.exception() is not None:
                    query.reply_err(str(fut.exception()).encode())
                else:
                    att = pack_attachment(attachment.sequence, time.time_ns(), attachment.gid)
                    query.reply(query.key_expr, serialize(fut.result()), attachment=att)
                    self._sent += 1
            except Exception as err:  # noqa: BLE001
                self._warn("reply", f"could not answer a request on {service.srv_name}: {err}")
            finally:
                query.drop()

        future.add_done_callback(done)
        service.node._call_soon(service._enqueue, _Call(request, loop, future, attachment.gid, attachment.sequence))

    def _query(self, server: _RemoteServer, call: _Call) -> None:
        """Send ``call`` to a remote server; the reply completes the caller's future."""
        import zenoh

        from ..msgs import DeserializationError, deserialize, serialize

        state = {"answered": False}
        gid = self._client_gid
        seq = next(self._ids)

        def on_reply(reply: Any) -> None:
            if state["answered"]:
                return
            state["answered"] = True
            if reply.ok is None:
                err = reply.err
                text = err.payload.to_bytes().decode(errors="replace") if err is not None else "error"
                _reply(call, exc=ServiceError(f"service {server.srv_name} failed: {text}"))
                return
            try:
                response = deserialize(reply.ok.payload.to_bytes(), server.srv_type.Response)
            except DeserializationError as err:
                self._warn("reply", f"dropped a reply on {server.srv_name}: {err}")
                _reply(call, exc=ServiceError(f"service {server.srv_name} sent a malformed reply: {err}"))
                return
            self._received += 1
            _reply(call, result=response)

        def on_done() -> None:
            if not state["answered"]:
                _reply(call, exc=ServiceError(f"service {server.srv_name} ended the call without a reply"))

        try:
            payload = serialize(call.request)
            self._session.get(
                server.key,
                zenoh.handlers.Callback(on_reply, on_done),
                target=zenoh.QueryTarget.ALL_COMPLETE,
                consolidation=zenoh.ConsolidationMode.NONE,
                payload=payload,
                attachment=pack_attachment(seq, time.time_ns(), gid),
                timeout=QUERY_TIMEOUT_SEC,
            )
            self._sent += 1
        except Exception as err:  # noqa: BLE001
            _reply(call, exc=ServiceError(f"service {server.srv_name}: could not send the request: {err}"))

    @property
    def _client_gid(self) -> bytes:
        return gid_of(f"@ros2_lv/{self.domain_id}/{self._zid}/client")

    # -- discovery -------------------------------------------------------------------------

    def _on_token(self, sample: Any) -> None:
        import zenoh

        alive = sample.kind == zenoh.SampleKind.PUT
        self._to_loop(self._token_event, str(sample.key_expr), alive)

    def _token_event(self, token: str, alive: bool) -> None:
        """On the main loop: a remote entity appeared or left."""
        if self.bus is None:
            return
        try:
            info = parse_token(token)
        except WireError as err:
            self._warn("token", f"ignored a liveliness token: {err}")
            return
        if info.zid == self._zid:
            return
        with self._lock:
            if not alive:
                self._forget(token)
                return
            if token in self._remote or token in self._describing:
                return
            try:
                self._learn(info)
            except Exception as err:  # noqa: BLE001 - a bad peer must not break discovery
                self._warn("token", f"could not add remote {info.kind} {info.topic or info.node}: {err}")

    def _learn(self, info: Any) -> None:
        from .._core._graph import NodeInfo
        from ..msgs import get

        bus = self.bus
        assert bus is not None
        if info.kind == "NN":
            self._remote_nodes[info.token] = NodeInfo(info.node, info.namespace, info.node_fqn, "remote")
            self._remote[info.token] = None
            return
        try:
            cls = get(info.type_name)
        except Exception:
            if info.kind == "MP" and self._ask_description(info):
                return  # learnt again once the publisher's node has described the type
            self._remote[info.token] = None  # a type this process does not know: nothing to deliver
            return
        local_hash = self._hash(cls)
        if local_hash != info.type_hash:
            self._warn(
                "type_hash",
                f"remote {info.kind} of {info.node_fqn} on {info.topic} uses {info.type_name} with hash "
                f"{info.type_hash}, this process has {local_hash}: they do not connect",
            )
            self._remote[info.token] = None
            return
        if info.kind == "MP":
            injector = _Injector(self._owner, cls, info.topic, info.qos, info.node_fqn, fresh=True)
            self._remote[info.token] = injector
            self._by_gid[gid_of(info.token)] = injector
            self._add_to_bus(injector)
            inb = self._inbound.get((info.topic, info.type_name))
            if inb is not None and inb.advanced and info.qos.durability is DurabilityPolicy.TRANSIENT_LOCAL:
                self._ask_history(inb, info.zid)
        elif info.kind == "MS":
            tap = Tap(cls, info.topic, info.qos, _ignore, owner=info.node_fqn, keeps=False)
            self._remote[info.token] = tap
            self._add_to_bus(tap)
            key = (info.topic, info.type_hash)
            self._sub_zids.setdefault(key, Counter())[info.zid] += 1
            self._refresh_iox(key)
        elif info.kind == "SS":
            if info.topic == f"{info.node_fqn.rstrip('/')}/get_type_description":
                self._describers.add(info.node_fqn)
                self._describe_again(info.node_fqn)
            key = data_key(self.domain_id, info.topic, info.type_name, info.type_hash)
            server = _RemoteServer(self, cls, info.topic, key, info.node_fqn)
            self._remote[info.token] = server
            bus.services.add(server)  # type: ignore[arg-type]
        elif info.kind == "SC":
            client = _RemoteClient(info.type_name, info.topic, info.node_fqn)
            self._remote[info.token] = client
            bus.services.add(client)  # type: ignore[arg-type]

    def _ask_description(self, info: Any) -> bool:
        """Ask the publishing node's ``~/get_type_description`` (every ROS 2 Jazzy node serves it, and
        aiorobot's bag player) for a type this process does not know. True while an answer is awaited."""
        import zenoh

        from ..msgs import serialize
        from ..msgs.type_description_interfaces import GetTypeDescription

        key = (info.type_name, info.type_hash)
        state = self._descriptions.get(key)
        if state in ("known", "failed"):
            return False
        if state == "unanswered":  # the node's service was not there yet: wait for its token
            self._undescribed.setdefault(info.node_fqn, []).append(info)
            return False
        self._describing[info.token] = info
        if state == "asked":
            return True
        self._descriptions[key] = "asked"
        self._asks[key] += 1
        answered = {"done": False}

        def on_reply(reply: Any) -> None:
            if answered["done"] or reply.ok is None:
                return
            answered["done"] = True
            self._to_loop(self._on_description, key, info.node_fqn, reply.ok.payload.to_bytes())

        def on_done() -> None:
            if not answered["done"]:
                self._to_loop(self._on_description, key, info.node_fqn, None)

        srv_key = data_key(self.domain_id, f"{info.node_fqn}/get_type_description", GetTypeDescription.__msgtype__,
                           self._hash(GetTypeDescription))
        request = GetTypeDescription.Request(type_name=info.type_name, type_hash=info.type_hash, include_type_sources=False)
        self._session.get(
            srv_key,
            zenoh.handlers.Callback(on_reply, on_done),
            target=zenoh.QueryTarget.ALL_COMPLETE,
            payload=serialize(request),
            attachment=pack_attachment(next(self._ids), time.time_ns(), self._client_gid),
            timeout=DESCRIBE_TIMEOUT_SEC,
        )
        return True

    def _on_description(self, key: tuple[str, str], node: str, payload: bytes | None) -> None:
        """On the main loop: register the described type, then learn the endpoints that waited for it."""
        from ..msgs import deserialize, register_type_description
        from ..msgs.type_description_interfaces import GetTypeDescription

        ok = False
        if payload is not None:
            try:
                response = deserialize(payload, GetTypeDescription.Response)
                if not response.successful:
                    raise ValueError(response.failure_reason or "no reason given")
                register_type_description(response.type_description)
                ok = True
            except Exception as err:  # noqa: BLE001 - a bad answer leaves the type unknown, as before
                _log.warning(f"{node} described type {key[0]}, but it cannot be used: {err}")
        self._descriptions[key] = "known" if ok else "failed" if payload is not None else "unanswered"
        if self.bus is None:
            return
        with self._lock:
            for token, info in list(self._describing.items()):
                if (info.type_name, info.type_hash) != key:
                    continue
                del self._describing[token]
                self._remote[token] = None
                if payload is None:  # no get_type_description at that node (yet): ask when it appears
                    self._undescribed.setdefault(info.node_fqn, []).append(info)
                    asks = self._asks[key]
                    if info.node_fqn in self._describers and asks < DESCRIBE_ATTEMPTS and self._loop is not None:
                        # it appeared while the query was on its way, or its queryable's route is not
                        # up yet (its liveliness token came first): ask again, backing off
                        self._loop.call_later(
                            min(0.05 * 2**asks, 2.0), self._describe_again_if_open, info.node_fqn
                        )
                elif ok:
                    try:
                        self._learn(info)
                    except Exception as err:  # noqa: BLE001 - a bad peer must not break discovery
                        self._warn("token", f"could not add remote {info.kind} {info.topic}: {err}")

    def _describe_again_if_open(self, node: str) -> None:
        if self.bus is not None and self._session is not None:
            with self._lock:
                self._describe_again(node)

    def _describe_again(self, node: str) -> None:
        """``node``'s ``get_type_description`` appeared: ask it about the types it could not describe before."""
        for info in self._undescribed.pop(node, []):
            if info.token in self._remote and self._remote[info.token] is None:
                self._descriptions.pop((info.type_name, info.type_hash), None)
                del self._remote[info.token]
                if not self._ask_description(info):
                    self._remote[info.token] = None

    def _add_to_bus(self, endpoint: Any) -> None:
        assert self.bus is not None
        try:
            if isinstance(endpoint, Publisher):
                self.bus.add_publisher(endpoint)
            else:
                self.bus.add_subscription(endpoint)
        except Exception as err:  # noqa: BLE001 - strict_qos refuses it: the warning is the report
            _log.error(f"remote endpoint not connected: {err}")
            self._remote[next(t for t, e in self._remote.items() if e is endpoint)] = None

    def _forget(self, token: str) -> None:
        self._describing.pop(token, None)
        entry = self._remote.pop(token, None)
        self._remote_nodes.pop(token, None)
        bus = self.bus
        if entry is None or bus is None:
            return
        if isinstance(entry, _Injector):
            gid = gid_of(token)
            self._by_gid.pop(gid, None)
            inb = self._inbound.get((entry.topic_name, entry.type_name))
            if inb is not None:
                inb._delivered.forget(gid)
                inb._last_seq.pop(gid, None)
            entry.destroyed = True
            bus.remove(entry)
        elif isinstance(entry, Tap):
            bus.remove(entry)
            info = parse_token(token)
            zids = self._sub_zids.get((info.topic, info.type_hash))
            if zids is not None:
                zids[info.zid] -= 1
                if zids[info.zid] <= 0:
                    del zids[info.zid]
                self._refresh_iox((info.topic, info.type_hash))
        else:
            entry.destroyed = True
            bus.services.remove(entry)


def build_session_config(
    *,
    config_file: str | None = None,
    connect: list[str] | None = None,
    listen: list[str] | None = None,
    shared_memory: bool | None = None,
    allow_plain: tuple[str, ...] | list[str] = (),
) -> tuple[Any, SessionPlan]:
    """The ``zenoh.Config`` a :class:`ZenohTransport` opens, and what it will do, checked.

    Raises :class:`ZenohConfigError` (one line: file, key, problem) for a file that does not
    parse, a certificate or key that is not there, or a plain endpoint in a secured config.
    """
    import zenoh

    path = config_file
    named_by = None
    if not path and os.environ.get("ZENOH_SESSION_CONFIG_URI", "").strip():
        path, named_by = os.environ["ZENOH_SESSION_CONFIG_URI"].strip(), "ZENOH_SESSION_CONFIG_URI"
    if path:
        cfg = load_config_file(path, named_by=named_by)
    else:
        cfg = zenoh.Config()
        cfg.insert_json5("mode", '"peer"')
        cfg.insert_json5("scouting/multicast/enabled", "false")
        cfg.insert_json5("listen/endpoints", json.dumps(listen or [DEFAULT_LISTEN]))
        cfg.insert_json5("connect/endpoints", json.dumps(connect if connect is not None else [DEFAULT_CONNECT]))
        # zenoh's transmit batching stays on (its default and rmw_zenoh's): it batches only under
        # back-pressure, so a steady stream is not held back, and a stall of the transmit thread
        # fills a batch instead of two one-message slots that then drop (docs/zenoh.md)
        # Large messages (images, clouds) to peers on this host go through shared memory;
        # zenoh falls back to the network for a peer that cannot map it.
        cfg.insert_json5("transport/shared_memory/enabled", "true")
    cfg.insert_json5("timestamping/enabled", "true")  # the advanced publisher's cache needs it
    if shared_memory is not None:
        cfg.insert_json5("transport/shared_memory/enabled", json.dumps(bool(shared_memory)))
    apply_overrides(cfg, os.environ.get("ZENOH_CONFIG_OVERRIDE", ""))
    plan = plan_of(cfg, path or DEFAULT_SOURCE)
    check_plan(plan, allowed_plain(allow_plain))
    return cfg, plan


def _skip_router_check() -> bool:
    """``ZENOH_ROUTER_CHECK_ATTEMPTS`` < 0 skips rmw_zenoh's router check; it skips the warning here."""
    raw = os.environ.get("ZENOH_ROUTER_CHECK_ATTEMPTS", "").strip()
    try:
        return int(raw) < 0
    except ValueError:
        return False


def _unlinked(session: Any, endpoints: tuple[str, ...]) -> list[str]:
    """Of ``endpoints``, those the session holds no link to (zenoh tried each once in ``open``)."""
    import socket

    linked: set[tuple[str, str, int]] = set()
    for link in session.info.links():
        proto, target = str(link.dst).split("/", 1)[0].lower(), host_port(str(link.dst))
        if target is not None:
            linked.add((proto, target[0], target[1]))
    missing = []
    for endpoint in endpoints:
        target = host_port(endpoint)
        if target is None:
            continue  # not an IP endpoint (unix socket, serial): zenoh's own word stands
        proto = endpoint.split("/", 1)[0].lower()
        try:
            addresses = {info[4][0] for info in socket.getaddrinfo(target[0], target[1], proto=socket.IPPROTO_TCP)}
        except OSError:
            addresses = {target[0]}
        if not any((proto, a, target[1]) in linked for a in addresses):
            missing.append(endpoint)
    return missing


def _refusal(plan: SessionPlan, err: BaseException) -> str:
    """The one line for a session zenoh would not open (client mode reaching no router, ...)."""
    text = zenoh_error_text(err)
    if "Unable to connect" not in text or not plan.connect:
        return f"zenoh could not open the session ({plan.mode} mode, {plan.source}): {text}"
    reasons = "; ".join(f"{ep}: {why_unreachable(ep, plan.tls)}" for ep in plan.connect)
    return f"zenoh session refused ({plan.mode} mode, {plan.source}): {reasons}"


def _undeclare(querier: tuple[Any, ...]) -> None:
    """Undeclare a history querier and its matching listener, the listener first."""
    for entity in reversed(querier):
        entity.undeclare()


def _ignore(_msg: Any) -> None:
    """A remote subscription's tap: the sender tap of the topic does the sending."""


def _own_tap(endpoint: Any) -> bool:
    """A tap that is not a subscriber of remote data (the transport's own outbound taps): recorders,
    bridges and the runtime's /clock tap mark theirs with ``wants_remote``."""
    return isinstance(endpoint, Tap) and not getattr(endpoint, "wants_remote", False)
