"""iceoryx2 as the same-host data path of large messages between aiorobot processes (issue 27),
beside zenoh, chosen per receiving process: ``ZenohTransport(iceoryx2_topics=...)``.

Discovery, the graph, services and every message that does not take this path stay on zenoh.
For a topic that takes it (listed, or ``"*"`` and a type that carries arrays):

* each process that subscribes it keeps its zenoh subscriber (other hosts, rmw_zenoh nodes, and
  every small message still arrive there) and adds an :class:`Iceoryx2Input`: an iceoryx2
  subscriber of the topic's service (derived from domain, topic and type hash) with a thread
  waiting on the service's event. Once it is connected, the process announces it with a zenoh
  liveliness token (:func:`token_key`) that names its iceoryx2 node;
* each process that publishes it (volatile publishers) has an :class:`Iceoryx2Sender`. While an
  iceoryx2 subscriber of another process is connected, a message of ``shm_threshold`` bytes or
  more (CDR) is serialised straight into a loaned sample (the CDR's parts, its arrays among
  them, copied once: ``build_parts_serializer``) behind the rmw_zenoh attachment (sequence
  number, timestamp, GID), and the event is notified. It is put on zenoh as well only when a
  remote subscription of the topic is not *served*: served means its session announced an
  input whose iceoryx2 node is attached to this very service (so it shares this host's shared
  memory). An rmw_zenoh node, another host, a session without the path, or a subscription
  whose token came before its session's announcement all get every message over zenoh;
* a process that gets a message both ways (a publisher that must also put on zenoh) delivers
  it once: the receiving :class:`~aiorobot.transport._zenoh._Inbound` drops a (GID, sequence
  number) it has already delivered (a window of :data:`WINDOW` numbers per publisher).

A message is decoded with ``view=True`` over the sample's memory, which stays loaned while the
message's arrays refer to it (the sample hangs on the buffer the arrays view); past
``BORROW_MAX - 1`` such samples, one is copied out instead. See docs/zenoh.md.
"""

from __future__ import annotations

import ctypes
import struct
import threading
import weakref
from typing import TYPE_CHECKING, Any

from ..msgs import DeserializationError as _DeserializationError
from ..msgs._cdr_gen import build_parts_serializer
from ..msgs._spec import SCALAR, SEQUENCE
from ._wire import ATTACHMENT_SIZE, demangle, mangle

if TYPE_CHECKING:
    from ._zenoh import ZenohTransport, _Inbound, _Outbound

__all__ = [
    "BORROW_MAX", "BUFFER_SIZE", "HEAD", "INITIAL_BYTES", "Iceoryx2Host", "Iceoryx2Input", "Iceoryx2Sender",
    "carries_arrays", "parse_token", "quiet", "token_key", "unavailable",
]

#: a sample's payload: the rmw_zenoh attachment (33 bytes), 7 bytes of padding, then the CDR (8-aligned)
HEAD = 40
_SEQ = struct.Struct("<q")
#: samples a subscriber holds queued (its buffer) and holds for messages still alive (borrowed)
BUFFER_SIZE = 8
BORROW_MAX = 8
#: publishers and subscribers of one topic's service, processes on the host together
MAX_PORTS = 16
#: how long the receiving thread waits for an event before it looks whether it should stop
WAIT_MS = 100
#: a sender's first slice length; larger messages get larger segments (power-of-two allocation)
INITIAL_BYTES = 64 * 1024
#: the liveliness tokens that announce a process's inputs: ``@aiorobot_iox/<domain>/<zid>/<node id>/<topic>/<hash>``
TOKEN_PREFIX = "@aiorobot_iox"
_SERIALIZERS: dict[type, Any] = {}
_ARRAYS: dict[type, bool] = {}


def unavailable() -> str | None:
    """Why this path cannot run here (None: it can)."""
    import importlib.util

    return None if importlib.util.find_spec("iceoryx2") else "iceoryx2 is not installed (pip install iceoryx2)"


def quiet() -> None:
    """iceoryx2's own log at errors only, unless ``IOX2_LOG_LEVEL`` says otherwise: at its default
    level every process that opens a node prints "No config file was loaded, a config with default
    values will be used." on stderr (what goes wrong here reaches us as an exception, and is said)."""
    import iceoryx2 as iox2

    iox2.set_log_level_from_env_or(iox2.LogLevel.Error)


def carries_arrays(msg_type: Any) -> bool:
    """Whether ``msg_type`` has an unbounded sequence of numbers (an Image's pixels, a cloud's
    points, a scan's ranges): the types ``iceoryx2_topics=["*"]`` sends over iceoryx2."""
    known = _ARRAYS.get(msg_type)
    if known is None:
        from ..msgs import get

        def walk(spec: Any) -> bool:
            for f in spec.fields:
                t = f.type
                if t.is_primitive and t.kind == SEQUENCE and not t.count:
                    return True
                if t.is_message and walk(get(t.base)._spec):
                    return True
            return False

        known = _ARRAYS[msg_type] = walk(msg_type._spec)
    return known


def token_key(domain_id: int, zid: str, node_id: int, topic: str, type_hash: str) -> str:
    return f"{TOKEN_PREFIX}/{domain_id}/{zid}/{node_id}/{mangle(topic)}/{type_hash}"


def parse_token(key: str) -> tuple[str, int, str, str]:
    """``(zid, iceoryx2 node id, topic, type hash)`` of an input's token; ValueError if malformed."""
    parts = key.split("/")
    if len(parts) != 6 or parts[0] != TOKEN_PREFIX:
        raise ValueError(f"expected {TOKEN_PREFIX}/<domain>/<zid>/<node id>/<topic>/<hash>, found {key!r}")
    return parts[2], int(parts[3]), demangle(parts[4]), parts[5]


class Iceoryx2Host:
    """A transport's iceoryx2 node and the services it opened (one per topic and type)."""

    def __init__(self) -> None:
        import iceoryx2 as iox2

        quiet()
        self._iox2 = iox2
        self.node = iox2.NodeBuilder.new().create(iox2.ServiceType.Ipc)
        self.node_id: int = self.node.id.value
        self._services: dict[str, tuple[Any, Any]] = {}
        self.cleanup()

    def service(self, name: str) -> tuple[Any, Any]:
        """The publish-subscribe service ``name`` and its event service (opened or created)."""
        found = self._services.get(name)
        if found is None:
            iox2 = self._iox2
            data = (
                self.node.service_builder(iox2.ServiceName.new(name))
                .publish_subscribe(iox2.Slice[ctypes.c_uint8])
                .max_publishers(MAX_PORTS)
                .max_subscribers(MAX_PORTS)
                .subscriber_max_buffer_size(BUFFER_SIZE)
                .subscriber_max_borrowed_samples(BORROW_MAX)
                .open_or_create()
            )
            event = (
                self.node.service_builder(iox2.ServiceName.new(name + "/event"))
                .event()
                .max_notifiers(MAX_PORTS)
                .max_listeners(MAX_PORTS)
                .open_or_create()
            )
            found = self._services[name] = (data, event)
        return found

    def attached(self, name: str, node_id: int) -> bool:
        """Whether the iceoryx2 node ``node_id`` is alive and attached to the service ``name``: it
        maps this host's shared memory (a node on another host is not in the service's list)."""
        data, _ = self.service(name)
        for state in data.nodes:
            if isinstance(state, self._iox2.NodeState.Alive) and state._0.id.value == node_id:
                return True
        return False

    def cleanup(self) -> None:
        """Release what processes that died (SIGKILL) left: their ports count against a service's
        publishers and subscribers, and their queued samples against the publishers' pools."""
        try:
            self.node.try_cleanup_dead_nodes()
        except Exception:  # noqa: BLE001 - another process is cleaning up: it will be done
            pass

    def close(self) -> None:
        self._services.clear()
        self.node = None


class Iceoryx2Sender:
    """The iceoryx2 side of one topic's :class:`~aiorobot.transport._zenoh._Outbound`."""

    def __init__(self, host: Iceoryx2Host, outbound: _Outbound, service: str) -> None:
        import iceoryx2 as iox2

        self.topic = outbound.topic
        data, event = host.service(service)
        self._publisher = (
            data.publisher_builder()
            .initial_max_slice_len(INITIAL_BYTES)
            .allocation_strategy(iox2.AllocationStrategy.PowerOfTwo)
            .create()
        )
        self._notifier = event.notifier_builder().create()
        self._config = data.dynamic_config
        self.own = 0  # this process's own input on the service (it counts as a subscriber)
        serialize = _SERIALIZERS.get(outbound.msg_type)
        if serialize is None:
            serialize = _SERIALIZERS[outbound.msg_type] = build_parts_serializer(outbound.msg_type)
        self.serialize = serialize
        self._lock = threading.Lock()
        self.sent = 0

    def wanted(self) -> bool:
        """An input of another process is connected (0.1 us to ask)."""
        return self._config.number_of_subscribers > self.own

    def send(self, head: bytes, parts: list[Any], size: int) -> str | None:
        """Copy ``head`` and the CDR ``parts`` into a loaned sample, send it and notify. None when
        sent, else what went wrong (every sample still held by subscribers, a closed sender)."""
        with self._lock:
            publisher = self._publisher
            if publisher is None:
                return "closed"
            try:
                sample = publisher.loan_slice_uninit(HEAD + size)
            except Exception as err:  # noqa: BLE001 - LoanError: every sample still held by subscribers
                return f"{type(err).__name__}: {err}"
            dst = memoryview((ctypes.c_uint8 * (HEAD + size)).from_address(sample.payload_ptr)).cast("B")
            dst[:ATTACHMENT_SIZE] = head
            pos = HEAD
            for part in parts:
                part = memoryview(part).cast("B")
                end = pos + part.nbytes
                dst[pos:end] = part
                pos = end
            del dst
            sample.assume_init().send()
            self._notifier.notify()
            self.sent += 1
        return None

    def close(self) -> None:
        with self._lock:
            for port in (self._publisher, self._notifier):
                if port is not None:
                    port.delete()
            self._publisher = self._notifier = None


class Iceoryx2Input:
    """The iceoryx2 side of one topic's :class:`~aiorobot.transport._zenoh._Inbound`: a thread
    waits on the service's event, takes the samples, decodes each and queues it in the inbound's
    inbox, as zenoh's thread does with its samples."""

    def __init__(self, host: Iceoryx2Host, inbound: _Inbound, service: str) -> None:
        import iceoryx2 as iox2

        self.inbound = inbound
        self.transport: ZenohTransport = inbound.transport
        data, event = host.service(service)
        self._subscriber = data.subscriber_builder().buffer_size(BUFFER_SIZE).create()
        self._listener = event.listener_builder().create()
        self._wait = iox2.Duration.from_millis(WAIT_MS)
        self._held = 0  # samples loaned to messages still alive
        self._held_lock = threading.Lock()
        self.copied = 0  # messages copied out of their sample (too many samples held)
        self.received = 0
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._pump, name=f"aiorobot-iceoryx2 {inbound.topic}", daemon=True)
        self._thread.start()

    def _pump(self) -> None:
        transport, inbound = self.transport, self.inbound
        subscriber, listener = self._subscriber, self._listener
        while not self._stop.is_set():
            try:
                if not listener.timed_wait(self._wait):
                    continue
                while (sample := subscriber.receive()) is not None:
                    decoded = self._decode(sample)
                    del sample  # not borrowed while the next one is taken (one held past BORROW_MAX - 1)
                    if decoded is not None:
                        (inbound.inbox or transport._inbox).put(inbound, decoded)
            except Exception as err:  # noqa: BLE001 - say it, keep receiving
                if not self._stop.is_set():
                    transport._warn("iceoryx2", f"receiving {inbound.topic} over iceoryx2: {type(err).__name__}: {err}")

    def _decode(self, sample: Any) -> tuple[bytes, Any, int, bool] | None:
        """On the receiving thread: ``(gid, message, sequence number)``, the message's arrays
        viewing the sample; None for this process's own messages and for what is dropped."""
        transport = self.transport
        size = sample.header.number_of_elements  # (bytes; ``payload()`` would build a Slice first)
        buf = (ctypes.c_uint8 * size).from_address(sample.payload_ptr)
        try:
            if size < HEAD + 4:
                raise _DeserializationError(f"expected at least {HEAD + 4} bytes, found {size}")
            head = bytes(buf[:ATTACHMENT_SIZE])
            if head[16] != 16:
                raise _DeserializationError(f"expected a 16-byte GID after the sequence number and time, found {head[16]} bytes")
            gid = head[17:]
            if gid in transport._own_gids:
                return None  # published here: its subscriptions had it from the bus
            with self._held_lock:
                hold = self._held < BORROW_MAX - 1
                self._held += hold
            if hold:
                buf._sample = sample  # type: ignore[attr-defined]  # loaned while the message's arrays view it
                weakref.finalize(buf, self._released)
                data: Any = memoryview(buf).cast("B")[HEAD:].toreadonly()  # read-only views
            else:
                data = bytes(memoryview(buf).cast("B")[HEAD:])
                self.copied += 1
            msg = self.inbound.decode(data)
        except Exception as err:  # noqa: BLE001 - nothing from another process may escape
            transport._drop_sample(f"{self.inbound.topic} (iceoryx2)", err)
            return None
        transport._received_iox += 1
        self.received += 1
        return gid, msg, _SEQ.unpack_from(head)[0], True

    def _released(self) -> None:
        with self._held_lock:
            self._held -= 1

    def close(self) -> None:
        if self._stop.is_set():
            return
        self._stop.set()
        if self._thread is not threading.current_thread():
            self._thread.join()
        # the ports are dropped, not deleted: samples still viewed by messages keep what they need
        self._subscriber = self._listener = None
