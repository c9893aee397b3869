"""A prototype same-host data path for large messages over iceoryx2 (issue 27): experimental, not a
transport of its own, not used by default.

One topic between two aiorobot processes on one host, both running a :class:`ZenohTransport`
(discovery, the graph and every other topic stay on zenoh):

* :class:`Iceoryx2Sender` puts a bus tap (``Tap(keeps=False)``) on the topic that serialises each
  message published in this process straight into a sample loaned from iceoryx2's shared memory
  (the CDR's parts, its arrays among them, copied once: ``build_parts_serializer``), sends it and
  notifies the service's event;
* :class:`Iceoryx2Receiver` stands in for the topic's zenoh subscriber (an ``_Inbound`` whose data
  comes from iceoryx2): a thread waits on the event listener, takes the samples and hands each to
  the transport's own queue (``ZenohTransport._queue``: wake the loop, decode on this thread,
  ``_drain`` injects on the loop as it does for zenoh's samples). A message is decoded with
  ``deserialize(..., view=True)`` over the sample's memory, which stays loaned while the message's
  arrays refer to it (the sample hangs on the buffer the arrays view); past ``BORROW_MAX - 1`` such
  samples, one is copied out instead.

Both sides are told the iceoryx2 service name; an adoption would agree on it over zenoh (the
publisher's liveliness token). The payload is the publisher's 16-byte GID followed by the CDR, so
the message is injected as coming from its remote publisher, as over zenoh. The receiving side's
subscription declares no zenoh subscriber for the topic, so the sending side's zenoh publisher
finds no match and sends nothing there: each message travels once. See docs/zenoh.md.
"""

from __future__ import annotations

import ctypes
import threading
import weakref
from typing import Any

from .._core._pubsub import Tap
from ..msgs import DeserializationError as _DeserializationError
from ..msgs._cdr_gen import build_parts_serializer
from ._zenoh import _ANY_QOS, ZenohTransport, _Inbound

__all__ = ["BORROW_MAX", "BUFFER_SIZE", "INITIAL_BYTES", "Iceoryx2Receiver", "Iceoryx2Sender", "quiet", "unavailable"]

GID_BYTES = 16
#: samples a subscriber holds queued (its buffer) and holds for messages still alive (borrowed)
BUFFER_SIZE = 8
BORROW_MAX = 8
#: how long the receiving thread waits for an event before it looks whether it should stop
WAIT_MS = 100
#: a sender's first slice length when ZenohTransport(iceoryx2_topics=) makes it; larger messages
#: get larger segments (iceoryx2's power-of-two allocation)
INITIAL_BYTES = 64 * 1024
_SERIALIZERS: dict[type, Any] = {}


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


def _open(service: str) -> tuple[Any, Any, Any]:
    """This process's iceoryx2 node, and the topic's publish-subscribe and event services."""
    import iceoryx2 as iox2

    quiet()
    node = iox2.NodeBuilder.new().create(iox2.ServiceType.Ipc)
    # what processes that died (SIGKILL) left behind: their ports count against a service's
    # publishers and subscribers until some process releases them
    node.try_cleanup_dead_nodes()
    data = (
        node.service_builder(iox2.ServiceName.new(service))
        .publish_subscribe(iox2.Slice[ctypes.c_uint8])
        .subscriber_max_buffer_size(BUFFER_SIZE)
        .subscriber_max_borrowed_samples(BORROW_MAX)
        .open_or_create()
    )
    event = node.service_builder(iox2.ServiceName.new(service + "/event")).event().open_or_create()
    return node, data, event


class Iceoryx2Sender:
    """Sends every message published on ``topic`` in this process over the iceoryx2 ``service``
    (``max_bytes``: the CDR size to expect; larger messages get larger segments). It stays on the
    bus until :meth:`close`."""

    def __init__(self, transport: ZenohTransport, msg_type: Any, topic: str, service: str, *, max_bytes: int) -> None:
        import iceoryx2 as iox2

        if transport.bus is None:
            raise RuntimeError("Iceoryx2Sender: expected an open ZenohTransport (inside its Runtime), found a closed one")
        self.transport = transport
        self.topic = topic
        self.msg_type = msg_type
        self._node, data, event = _open(service)
        self._publisher = (
            data.publisher_builder()
            .initial_max_slice_len(max_bytes)
            .allocation_strategy(iox2.AllocationStrategy.PowerOfTwo)
            .create()
        )
        self._notifier = event.notifier_builder().create()
        self._service = data
        self.skipped = 0  # messages not serialised: no iceoryx2 subscriber was connected
        serialize = _SERIALIZERS.get(msg_type)
        if serialize is None:
            serialize = _SERIALIZERS[msg_type] = build_parts_serializer(msg_type)
        self._serialize = serialize
        self._gid = b""
        self._lock = threading.Lock()
        self.sent = 0
        self.tap = Tap(msg_type, topic, _ANY_QOS, self._send, owner="<iceoryx2>", keeps=False)
        transport.bus.add_subscription(self.tap)

    def _send(self, msg: Any) -> None:
        """The tap's callback, in the publishing thread: serialise into a loaned sample, send, notify."""
        transport = self.transport
        if transport._local.injecting:
            return  # it came from another process: do not echo it back
        if not self._service.dynamic_config.number_of_subscribers:
            self.skipped += 1  # nobody to send it to (0.1 us to ask; serialising an image: ~100 us)
            return
        try:
            parts, size = self._serialize(msg)
        except (TypeError, ValueError) as err:
            transport._warn("serialize", f"cannot send a message on {self.topic} over iceoryx2: {err}")
            return
        with self._lock:
            if self._publisher is None:
                return
            if not self._gid:
                out = transport._outbound.get((self.topic, self.msg_type.__msgtype__))
                self._gid = out._tail[1:] if out is not None else b"\0" * GID_BYTES
            try:
                sample = self._publisher.loan_slice_uninit(GID_BYTES + size)
            except Exception as err:  # noqa: BLE001 - LoanError: every sample still held by subscribers
                transport._warn("iceoryx2", f"cannot send a message on {self.topic} over iceoryx2: {type(err).__name__}: {err}")
                return
            dst = memoryview((ctypes.c_uint8 * (GID_BYTES + size)).from_address(sample.payload_ptr)).cast("B")
            dst[:GID_BYTES] = self._gid
            pos = GID_BYTES
            for part in parts:
                part = memoryview(part).cast("B")
                end = pos + part.nbytes
                dst[pos:end] = part
                pos = end
            del dst
            sample.assume_init().send()
            self._notifier.notify()
            self.sent += 1

    def close(self) -> None:
        bus = self.transport.bus
        if bus is not None:
            bus.remove(self.tap)
        with self._lock:
            for port in (self._publisher, self._notifier):
                if port is not None:
                    port.delete()
            self._publisher = self._notifier = None


class Iceoryx2Receiver(_Inbound):
    """Receives ``topic`` from the iceoryx2 ``service`` in place of a zenoh subscriber.

    Create it before the topic's first subscription in this process; the subscriptions then
    declare their liveliness tokens over zenoh (the graph sees them) but no zenoh subscriber.
    It closes with the transport, or when the topic's last subscription leaves.
    """

    def __init__(self, transport: ZenohTransport, msg_type: Any, topic: str, service: str) -> None:
        import iceoryx2 as iox2

        bus = transport.bus
        if bus is None:
            raise RuntimeError("Iceoryx2Receiver: expected an open ZenohTransport (inside its Runtime), found a closed one")
        key = (topic, msg_type.__msgtype__)
        if key in transport._inbound:
            raise RuntimeError(
                f"Iceoryx2Receiver: expected no subscription on {topic} yet, found one receiving over zenoh; "
                "create the receiver before the topic's subscriptions"
            )
        super().__init__(transport, topic, msg_type, transport._hash(msg_type))
        self._node, data, event = _open(service)
        self._subscriber = data.subscriber_builder().buffer_size(BUFFER_SIZE).create()
        self._listener = event.listener_builder().create()
        self._wait = iox2.Duration.from_millis(WAIT_MS)
        self._held = 0  # samples loaned to messages still alive
        self._held_lock = threading.Lock()
        self.copied = 0  # messages copied out of their sample (too many samples held)
        self.zsub = self._subscriber  # the transport's drain skips an inbound whose zsub is None
        transport._inbound[key] = self
        bus.add_publisher(self.fallback)
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._pump, name=f"aiorobot-iceoryx2 {topic}", daemon=True)
        self._thread.start()

    def declare(self, qos: Any) -> None:
        """No zenoh subscriber: the topic's data comes over iceoryx2."""

    def _pump(self) -> None:
        transport, subscriber, listener = self.transport, self._subscriber, self._listener
        while not self._stop.is_set():
            try:
                if not listener.timed_wait(self._wait):
                    continue
                while (sample := subscriber.receive()) is not None:
                    transport._queue(self, sample)
                    del sample  # not borrowed while the next one is taken (one held past BORROW_MAX - 1)
            except Exception as err:  # noqa: BLE001 - say it, keep receiving
                transport._warn("iceoryx2", f"receiving {self.topic} over iceoryx2: {type(err).__name__}: {err}")

    def _decode(self, sample: Any) -> tuple[bytes, Any] | None:
        """On the receiving thread: ``(gid, message)``, the message's arrays viewing the sample."""
        transport = self.transport
        size = sample.header.number_of_elements  # (bytes; ``payload()`` would build a Slice first)
        buf = (ctypes.c_uint8 * size).from_address(sample.payload_ptr)
        try:
            if size < GID_BYTES + 4:
                raise _DeserializationError(f"expected at least {GID_BYTES + 4} bytes, found {size}")
            gid = bytes(buf[:GID_BYTES])
            with self._held_lock:
                hold = self._held < BORROW_MAX - 1
                self._held += hold
            if hold:
                buf._sample = sample  # type: ignore[attr-defined]  # loaned while the message's arrays view it
                weakref.finalize(buf, self._released)
                data: Any = memoryview(buf).cast("B")[GID_BYTES:].toreadonly()  # read-only views
            else:
                data = bytes(memoryview(buf).cast("B")[GID_BYTES:])
                self.copied += 1
            msg = self.decode(data)
        except Exception as err:  # noqa: BLE001 - nothing from another process may escape
            transport._drop_sample(f"{self.topic} (iceoryx2)", err)
            return None
        transport._received += 1
        return gid, msg

    def _released(self) -> None:
        with self._held_lock:
            self._held -= 1

    def close(self) -> None:
        if self.zsub is None:
            return
        self.zsub = None
        self._stop.set()
        if self._thread is not threading.current_thread():
            self._thread.join()
        # the ports are dropped, not deleted: samples still viewed by messages keep what they need
        self._subscriber = self._listener = None
