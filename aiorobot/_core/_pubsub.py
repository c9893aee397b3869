"""Publishers and subscriptions of the in-process bus.

``publish`` hands subscribers a copy of the message made at publish, so a
publisher may change and publish its message again (the rclpy habit):

- scalar fields and nested messages are copied (about what constructing the
  message costs: ~1 us for a Twist);
- numpy arrays of at least ``SHARE_BYTES`` (4 KiB) are shared, not copied, and
  made read-only, the publisher's array too (an Image or PointCloud2 stays
  zero-copy; writing to the array after publish raises numpy's read-only error);
  smaller arrays are copied and read-only;
- sequences of strings and of messages become lists that refuse changes.

Every subscriber of one publish shares that one copy. What is enforced by
default: read-only arrays and sequences. Scalar fields and nested messages of a
received message can still be assigned; with ``Runtime(debug_messages=True)``
subscribers get a read-only twin instead, whose every assignment raises
``ReadOnlyMessageError`` naming the topic (and the deeper checks of
``aiorobot._core._mutation`` run).
A subscription owns a queue bounded by its QoS history (KEEP_LAST drops the
oldest when full) and one dispatcher task on its node's loop; messages from
another loop arrive through ``call_soon_threadsafe``.
"""

from __future__ import annotations

import asyncio
import inspect
import threading
import time
from collections import deque
from collections.abc import Callable
from typing import TYPE_CHECKING, Any, Generic, TypeVar

from ._handoff import post
from ._mutation import PublishGuard, digest
from ..msgs._classgen import freezer
from ._event_handler import Lease, PublisherEventCallbacks, SubscriptionEventCallbacks
from ._qos import DurabilityPolicy, LivelinessPolicy, QoSProfile, finite_ns

if TYPE_CHECKING:
    from ._groups import CallbackGroup
    from ._node import Node

__all__ = ["Endpoint", "MessageInfo", "MessageStream", "Publisher", "Subscription", "Tap"]

#: What a subscription callback taking two arguments gets besides the message, as rclpy's
#: ``rclpy.subscription.MessageInfo``: a dict with ``source_timestamp`` and
#: ``received_timestamp`` (system time, ns), ``publication_sequence_number`` (the
#: publisher's count, from 1; None when unknown) and ``reception_sequence_number``
#: (this subscription's count, from 1).
MessageInfo = dict

#: A dispatcher's marker for a message whose lifespan ran out while it was queued.
_EXPIRED = object()

M = TypeVar("M")

#: Messages a dispatcher handles before yielding to the loop when callbacks never suspend.
_BATCH = 64


class _EagerDelivery(threading.local):
    """While a transport delivers a received message (:func:`deliver_eagerly`), the idle
    subscriptions it wakes collect in ``ready`` instead of waking their dispatchers."""

    ready: list[Subscription[Any]] | None = None


_EAGER = _EagerDelivery()


def deliver_eagerly(publish: Callable[..., Any], *args: Any) -> None:
    """``publish(*args)`` (a transport handing a received message to the bus, on the loop of the
    subscriptions it is for), then run at once, in this call, the plain-function callbacks of the
    subscriptions it woke that were idle: their dispatchers would run them one loop iteration
    later, so a received message reaches its callback without that iteration. A subscription
    whose callback is a coroutine function, whose group is busy, or that takes MessageInfo (or
    was made with ``raw``, or runs under ``debug_messages``) is woken as with any publish; so is
    one that a callback run here publishes to (only the received message is delivered eagerly)."""
    with EagerBatch() as batch:
        publish(*args)
        if batch.ready:
            batch.run()


class EagerBatch:
    """:func:`deliver_eagerly` for a run of received messages (a transport's drain), its set-up
    done once for the run: ``with EagerBatch() as batch:``, then for each message its publish and
    ``if batch.ready: batch.run()``. Same semantics, message by message: the callbacks a
    message woke run before the next message is published, and a message published by one of
    them is not delivered eagerly."""

    __slots__ = ("ready",)

    def __init__(self) -> None:
        self.ready: list[Subscription[Any]] = []

    def __enter__(self) -> EagerBatch:
        _EAGER.ready = self.ready
        return self

    def run(self) -> None:
        """Run the callbacks the last message published woke, as :func:`deliver_eagerly` does."""
        ready = self.ready
        _EAGER.ready = None
        done = 0
        try:
            for sub in ready:
                done += 1
                sub._run_now()
        finally:
            for sub in ready[done:]:  # a callback raised (KeyboardInterrupt): their dispatchers take it
                sub._run_now(run=False)
            ready.clear()
            _EAGER.ready = ready

    def __exit__(self, *exc: object) -> None:
        _EAGER.ready = None
        for sub in self.ready:  # a publish raised: their dispatchers take what was queued
            sub._run_now(run=False)
        self.ready.clear()


def _type_name(msg_type: Any) -> str:
    return str(getattr(msg_type, "__msgtype__", None) or getattr(msg_type, "__name__", repr(msg_type)))


class Endpoint:
    """Something attached to a topic name: a publisher, subscription or tap."""

    kind = "endpoint"

    def __init__(self, node: Node | None, msg_type: Any, topic: str, qos: QoSProfile) -> None:
        self.node = node
        self.msg_type = msg_type
        self.topic_name = topic
        self.qos = qos
        self.destroyed = False

    @property
    def type_name(self) -> str:
        return _type_name(self.msg_type)

    @property
    def node_name(self) -> str:
        return self.node.get_fully_qualified_name() if self.node is not None else "<runtime>"

    def describe(self) -> str:
        return f"{self.kind} of {self.node_name} on {self.topic_name} [{self.type_name}, {self.qos.short()}]"


class Publisher(Endpoint, Generic[M]):
    """Publishes messages of one type on one topic; created by ``Node.create_publisher``."""

    kind = "publisher"
    node: Node

    def __init__(
        self,
        node: Node,
        msg_type: type[M],
        topic: str,
        qos: QoSProfile,
        *,
        event_callbacks: PublisherEventCallbacks | None = None,
        callback_group: CallbackGroup | None = None,
    ) -> None:
        super().__init__(node, msg_type, topic, qos)
        self.callback_group = callback_group
        # (message, (source ns, sequence number, expiry ns on the node clock) or None)
        self._history: deque[tuple[Any, Any]] | None = (
            deque(maxlen=qos.depth) if qos.durability is DurabilityPolicy.TRANSIENT_LOCAL else None
        )
        self._subs: tuple[Subscription | Tap, ...] = ()
        self._same_loop: tuple[Subscription, ...] = ()
        self._own_loop: asyncio.AbstractEventLoop | None = None
        # (loop, its thread's id, its subscriptions) for every loop but this publisher's own
        self._other_loops: tuple[tuple[asyncio.AbstractEventLoop, int | None, tuple[Subscription, ...]], ...] = ()
        self._taps: tuple[Tap, ...] = ()
        self._keepers = False  # a receiver keeps what is published: it gets a copy (see _accept)
        self._thread_id: int | None = None
        self._guard: PublishGuard | None = None  # Runtime(debug_messages=True)
        self._freeze = getattr(msg_type, "_cp", None)  # generated message classes only
        self._frozen_classes = freezer(topic)
        self.published = 0
        if event_callbacks is not None and not isinstance(event_callbacks, PublisherEventCallbacks):
            raise TypeError(f"event_callbacks: expected a PublisherEventCallbacks, found {event_callbacks!r}")
        self._events = (
            event_callbacks.create_event_handlers(callback_group, self) if event_callbacks is not None else {}
        )
        #: The QoS event handlers of this publisher (rclpy's attribute).
        self.event_handlers = list(self._events.values())
        # QoS watchers; None (no cost) for the default, infinite deadline and lease
        deadline = finite_ns(qos.deadline)
        lease = finite_ns(qos.liveliness_lease_duration)
        self._deadline = Lease(node, deadline, self._deadline_missed, repeat=True) if deadline else None
        self._liveliness = (
            Lease(node, lease, self._liveliness_lost, repeat=False)
            if lease and qos.liveliness is LivelinessPolicy.MANUAL_BY_TOPIC else None
        )
        self._alive = True
        self._lifespan_ns = finite_ns(qos.lifespan)
        self._info = False  # deliver (message, MessageInfo data) pairs instead of messages
        self._watched = False  # publish is _publish_watched
        self._choose_path(False)

    def __repr__(self) -> str:
        return (
            f"<Publisher {self.topic_name} {self.type_name} depth={self.qos.depth} "
            f"subscriptions={self.get_subscription_count()}>"
        )

    def get_subscription_count(self) -> int:
        """How many subscriptions (in this process and, with a transport, remote) receive this publisher."""
        return sum(1 for s in self._subs if not getattr(s, "hidden", False))

    def _choose_path(self, subscriber_wants_info: bool) -> None:
        """Publish through :meth:`_publish_watched` when a QoS watcher, a lifespan or a subscriber
        that takes MessageInfo needs it; otherwise through the plain :meth:`publish`."""
        self._info = self._lifespan_ns is not None or subscriber_wants_info
        # (a flag :meth:`publish` tests, not a method bound over it: ``pub.publish`` handed out as a
        # callback before a subscriber that takes MessageInfo matched must still serve it)
        self._watched = self._info or self._deadline is not None or self._liveliness is not None

    def _set_targets(self, subs: tuple[Subscription | Tap, ...], *, leaving: Endpoint | None = None) -> None:
        """Install the matched subscriptions (called by the bus under its lock); ``leaving``: the
        endpoint whose removal this is, which gets no ``matched`` event of its own."""
        self._report_matched(subs, leaving)
        before = {id(s): s for s in self._subs if isinstance(s, Subscription)}
        after = {id(s): s for s in subs if isinstance(s, Subscription)}
        for key, sub in before.items():
            if key not in after:  # unmatched: it no longer counts this publisher
                sub._liveliness_changed(-1, 0) if self._alive else sub._liveliness_changed(0, -1)
        for key, sub in after.items():
            if key not in before:
                sub._liveliness_changed(1, 0) if self._alive else sub._liveliness_changed(0, 1)
        self._choose_path(any(sub._wants_info for sub in after.values()))
        own_loop = self.node._loop
        self._thread_id = self.node._thread_id
        self._own_loop = own_loop
        same: list[Subscription] = []
        other: dict[asyncio.AbstractEventLoop, list[Subscription]] = {}
        taps: list[Tap] = []
        for sub in subs:
            loop = None if isinstance(sub, Tap) else sub.node._loop
            if isinstance(sub, Tap):
                taps.append(sub)
            elif loop is own_loop:
                same.append(sub)
            elif loop is not None:
                other.setdefault(loop, []).append(sub)
        self._subs = subs
        self._keepers = bool(same or other or any(tap.keeps for tap in taps))
        self._same_loop = tuple(same)
        self._other_loops = tuple((loop, group[0].node._thread_id, tuple(group)) for loop, group in other.items())
        self._taps = tuple(taps)

    def _report_matched(self, subs: tuple[Subscription | Tap, ...], leaving: Endpoint | None) -> None:
        """Count the connections ``subs`` makes and breaks on this publisher's ``matched`` handler and
        on those of the subscriptions concerned (a transport's hidden endpoints are nobody's peers)."""
        old = {id(s): s for s in self._subs if not getattr(s, "hidden", False)}
        new = {id(s): s for s in subs if not getattr(s, "hidden", False)}
        gained = [s for key, s in new.items() if key not in old]
        lost = [s for key, s in old.items() if key not in new]
        if not gained and not lost:
            return
        handler = self._events.get("matched")
        if handler is not None and self is not leaving:
            handler._fire(len(gained), len(gained) - len(lost))
        if getattr(self, "hidden", False):
            return
        for sub, deltas in [*((s, (1, 1)) for s in gained), *((s, (0, -1)) for s in lost)]:
            if isinstance(sub, Subscription) and sub is not leaving:
                sub_handler = sub._events.get("matched")
                if sub_handler is not None:
                    sub_handler._fire(*deltas)

    def publish(self, msg: M) -> None:
        """Hand a copy of ``msg`` (large arrays shared read-only) to every matched subscription.

        ``msg`` stays the caller's to change and publish again, except its numpy arrays of
        ``SHARE_BYTES`` or more, which subscribers share: those become read-only (assign a
        new array instead).

        rclpy difference: subscribers of one publish share one copy, whose arrays and
        sequences are read-only (docs/rclpy-differences.md).
        """
        if self._watched:
            self._publish_watched(msg)
            return
        msg = self._accept(msg)
        if self._history is not None:
            self._history.append((msg, None))
        if self._same_loop or self._other_loops:
            self._fan_out(msg)
        else:  # no subscription of this process: only taps take it (a transport sending it on)
            for tap in self._taps:
                tap._enqueue(msg)

    def _publish_watched(self, msg: M) -> None:
        """:meth:`publish` for a publisher with a finite deadline, lease or lifespan, or with a
        subscriber that takes MessageInfo: restarts its leases, and hands subscribers the
        message's source time, sequence number and expiry with it."""
        msg = self._accept(msg)
        if self._deadline is not None:
            self._deadline.touch()
        if self._liveliness is not None:
            self._assert_alive()
        if not self._info:
            if self._history is not None:
                self._history.append((msg, None))
            self._fan_out(msg)
            return
        lifespan = self._lifespan_ns
        expiry = self.node._clock.now_ns() + lifespan if lifespan is not None else None
        meta = (time.time_ns(), self.published, expiry)
        if self._history is not None:
            self._history.append((msg, meta))
        self._fan_out(msg, meta)

    def _accept(self, msg: M) -> M:
        """The checks and the copy every publish makes: the type, a destroyed publisher, the
        count, the copy subscribers share, the ``debug_messages`` guard."""
        if not isinstance(msg, self.msg_type):
            raise TypeError(
                f"publisher on {self.topic_name} expects {self.type_name}, got {type(msg).__name__}: {msg!r}"
            )
        if self.destroyed:
            raise RuntimeError(f"{self!r} was destroyed")
        self.published += 1
        if self._freeze is not None and (self._keepers or self._history is not None):
            msg = self._freeze(msg, self._frozen_classes)
        if self._guard is not None and not self._guard.check(msg):
            self.node.get_logger().error(
                f"debug_messages: a message published on {self.topic_name} was changed after publish "
                "(through an array it shares with subscribers); publish a new array each time",
                throttle_duration_sec=1.0,
            )
        return msg

    def _fan_out(self, msg: Any, meta: Any = None) -> None:
        """Hand ``msg`` (with ``meta``, the MessageInfo data, when not None) to every matched
        subscription: inline for those of the loop whose thread this is, posted to the others'
        loops; taps take ``msg`` inline. (A transport publishes what it received on the loop of the
        subscriptions it is for, the priority loop's included.)"""
        here = threading.get_ident()
        if here == self._thread_id:
            if meta is None:
                for sub in self._same_loop:
                    sub._enqueue(msg)
            else:
                _deliver_all(self._same_loop, msg, meta)
        elif self._same_loop and self._own_loop is not None:
            _post_to(self._own_loop, self._same_loop, msg, meta)
        for loop, thread_id, subs in self._other_loops:
            if thread_id == here:
                _deliver_all(subs, msg, meta) if meta is not None else _enqueue_all(subs, msg)
            else:
                _post_to(loop, subs, msg, meta)
        for tap in self._taps:
            tap._enqueue(msg)

    def assert_liveliness(self) -> None:
        """Assert that this publisher is alive without publishing (rclpy's), for
        ``LivelinessPolicy.MANUAL_BY_TOPIC``; a no-op for an ``AUTOMATIC`` publisher."""
        if self._liveliness is not None:
            self._assert_alive()

    def _assert_alive(self) -> None:
        assert self._liveliness is not None
        self._liveliness.touch()
        if not self._alive:
            self._alive = True
            for sub in self._subs:
                if isinstance(sub, Subscription):
                    sub._liveliness_changed(1, -1)

    def _liveliness_lost(self) -> None:
        self._alive = False
        handler = self._events.get("liveliness")
        if handler is not None:
            handler._fire(1)
        for sub in self._subs:
            if isinstance(sub, Subscription):
                sub._liveliness_changed(-1, 1)

    def _deadline_missed(self) -> None:
        handler = self._events.get("deadline")
        if handler is not None:
            handler._fire(1)

    def _start(self) -> None:
        """Start the QoS watchers (on the node's loop); a manual-liveliness publisher's first
        lease starts now."""
        if self._deadline is not None:
            self._deadline.start()
        if self._liveliness is not None:
            self._liveliness.touch()
            self._liveliness.start()

    def _stop(self) -> None:
        for lease in (self._deadline, self._liveliness):
            if lease is not None:
                lease.stop()

    def destroy(self) -> None:
        self.node.destroy_publisher(self)


def _deliver_all(subs: tuple[Subscription, ...], msg: Any, meta: Any) -> None:
    for sub in subs:
        sub._deliver(msg, meta)


def _enqueue_all(subs: tuple[Subscription, ...], msg: Any) -> None:
    for sub in subs:
        sub._enqueue(msg)


def _post_to(loop: asyncio.AbstractEventLoop, subs: tuple[Subscription, ...], msg: Any, meta: Any) -> None:
    if meta is None:
        post(loop, _enqueue_all, subs, msg)
    else:
        post(loop, _deliver_all, subs, msg, meta)


class Tap(Endpoint):
    """A subscription whose callback runs synchronously in the publishing thread.

    Used by the runtime (``/clock``) and by transports and recorders, which must see
    every message in publish order without a queue. The callback must be quick and
    thread-safe.
    """

    kind = "subscription"

    def __init__(
        self,
        msg_type: Any,
        topic: str,
        qos: QoSProfile,
        callback: Callable[[Any], None],
        *,
        owner: str = "<runtime>",
        keeps: bool = True,
    ) -> None:
        super().__init__(None, msg_type, topic, qos)
        self._enqueue = callback
        self.owner = owner
        #: The callback may keep the message past its return (a recorder's queue). False for a
        #: transport's outbound tap, which serialises it at once: a publisher whose only
        #: receivers are such taps makes no copy.
        self.keeps = keeps

    @property
    def node_name(self) -> str:
        return self.owner

    def __repr__(self) -> str:
        return f"<Tap {self.topic_name} {self.type_name} owner={self.owner}>"


class Subscription(Endpoint, Generic[M]):
    """Receives messages of one topic into a QoS-bounded queue; a dispatcher runs the callback.

    A message received from another process (zenoh, DDS, iceoryx2) while the dispatcher is idle
    runs a plain-function callback (not ``async def``, its callback group free) in its delivery
    instead, one loop turn sooner; ``asyncio.current_task()`` is then None in the callback
    (docs/zenoh.md, "eager delivery")."""

    kind = "subscription"
    node: Node

    def __init__(
        self,
        node: Node,
        msg_type: type[M],
        topic: str,
        callback: Callable[[M], Any] | None,
        qos: QoSProfile,
        group: CallbackGroup,
        *,
        event_callbacks: SubscriptionEventCallbacks | None = None,
        raw: bool = False,
    ) -> None:
        super().__init__(node, msg_type, topic, qos)
        self.callback = callback
        self.callback_group = group
        self.raw = raw
        #: The callback takes ``(msg, message_info)``, as rclpy decides (it cannot take one argument).
        self._wants_info = callback is not None and _takes_message_info(callback)
        self._queue: deque[Any] = deque()
        self._limit = qos.queue_limit
        self._waiter: asyncio.Future[None] | None = None
        self._task: asyncio.Task[None] | None = None
        self._busy = 0
        self._debug = False  # Runtime(debug_messages=True): check callbacks leave messages as they found them
        #: :func:`deliver_eagerly` may run the callback (set when the dispatcher starts)
        self._eager = False
        self.received = 0
        self.dropped = 0
        if event_callbacks is not None and not isinstance(event_callbacks, SubscriptionEventCallbacks):
            raise TypeError(f"event_callbacks: expected a SubscriptionEventCallbacks, found {event_callbacks!r}")
        self._events = event_callbacks.create_event_handlers(group, self) if event_callbacks is not None else {}
        #: The QoS event handlers of this subscription (rclpy's attribute).
        self.event_handlers = list(self._events.values())
        self._lost = self._events.get("message_lost")
        deadline = finite_ns(qos.deadline)
        self._deadline = Lease(node, deadline, self._deadline_missed, repeat=True) if deadline else None
        # In "info" mode a deque parallel to the queue holds each message's (publisher data or
        # None, received ns, reception number); plain subscriptions have none (no cost).
        self._infos: deque[tuple[Any, int, int]] | None = None
        if self._wants_info or self._deadline is not None or self._lost is not None:
            self._use_infos()

    def __repr__(self) -> str:
        return (
            f"<Subscription {self.topic_name} {self.type_name} depth={self.qos.depth} "
            f"queued={len(self._queue)}>"
        )

    @property
    def queued(self) -> int:
        return len(self._queue)

    def is_idle(self) -> bool:
        return not self._queue and self._busy == 0

    def _enqueue(self, msg: Any) -> None:
        """Put ``msg`` into the queue (on the node's loop thread only)."""
        if self.destroyed:
            return
        queue = self._queue
        if self._limit is not None and len(queue) >= self._limit:
            queue.popleft()
            self.dropped += 1
        queue.append(msg)
        self.received += 1
        waiter = self._waiter
        if waiter is not None:
            if self._eager:
                ready = _EAGER.ready
                if ready is not None:
                    ready.append(self)  # deliver_eagerly runs the callback, or wakes the dispatcher
                    return
            self._waiter = None
            if not waiter.done():
                waiter.set_result(None)

    def _run_now(self, *, run: bool = True) -> None:
        """For :func:`deliver_eagerly`: run the callback on the queued message here, as the idle
        dispatcher would, when the callback group is free (and ``run``); else wake the dispatcher."""
        waiter = self._waiter
        if waiter is None or waiter.done() or not self._queue or self.destroyed:
            return  # the dispatcher is running (or gone): it takes the message
        if run and self._infos is None:
            lock = self.callback_group._group_lock
            if lock is None or lock.try_acquire():
                self._busy += 1
                self.node._invoke_now(self, lock, self.callback, self._queue.popleft(), self._callback_done)
                return
        self._waiter = None
        waiter.set_result(None)

    def _use_infos(self) -> None:
        """Switch to info mode (on the node's loop thread): existing messages get no publisher data."""
        if self._infos is None:
            now = time.time_ns()
            self._infos = deque((None, now, 0) for _ in self._queue)
            self._enqueue = self._enqueue_without_info  # type: ignore[method-assign]

    def _enqueue_without_info(self, msg: Any) -> None:
        self._deliver(msg, None)

    def _deliver(self, msg: Any, meta: Any) -> None:
        """Put ``msg`` with its publisher data ``meta`` into the queue (on the node's loop thread)."""
        if self.destroyed:
            return
        if self._infos is None:
            self._use_infos()
        queue, infos = self._queue, self._infos
        assert infos is not None
        if self._limit is not None and len(queue) >= self._limit:
            queue.popleft()
            infos.popleft()
            self.dropped += 1
            if self._lost is not None:
                self._lost._fire(1)
        queue.append(msg)
        self.received += 1
        infos.append((meta, time.time_ns(), self.received))
        if self._deadline is not None:
            self._deadline.touch()
        waiter = self._waiter
        if waiter is not None:
            self._waiter = None
            if not waiter.done():
                waiter.set_result(None)

    def _take_info(self, msg: Any) -> Any:
        """The next queued message's info: ``_EXPIRED`` when its lifespan ran out, ``(msg,
        MessageInfo)`` for a callback that takes it, else ``msg``."""
        assert self._infos is not None
        meta, received_ns, number = self._infos.popleft()
        if meta is not None and meta[2] is not None and self.node._clock.now_ns() >= meta[2]:
            return _EXPIRED
        if not self._wants_info:
            return msg
        info: MessageInfo = {
            "source_timestamp": meta[0] if meta is not None else received_ns,
            "received_timestamp": received_ns,
            "publication_sequence_number": meta[1] if meta is not None else None,
            "reception_sequence_number": number,
        }
        return (msg, info)

    def _liveliness_changed(self, alive: int, not_alive: int) -> None:
        handler = self._events.get("liveliness")
        if handler is not None:
            handler._fire(alive, not_alive)

    def _deadline_missed(self) -> None:
        handler = self._events.get("deadline")
        if handler is not None:
            handler._fire(1)

    async def _wait(self) -> None:
        waiter = asyncio.get_running_loop().create_future()  # always the node's loop
        self._waiter = waiter
        try:
            await waiter
        finally:
            if self._waiter is waiter:
                self._waiter = None

    def _start(self) -> None:
        """Start the dispatcher and the deadline watcher (on the node's loop)."""
        if self._deadline is not None:
            self._deadline.start()
        if self.callback is not None and self._task is None:
            group = self.callback_group
            self._eager = (
                not (self._debug or self.raw or self._wants_info)
                and (group._group_lock is not None or not group.exclusive)
                and not _is_async(self.callback)
            )
            self._task = self.node._create_task(
                self._dispatch(), name=f"dispatch {self.topic_name} -> {self.node_name}"
            )

    async def _dispatch(self) -> None:
        node = self.node
        queue = self._queue
        group = self.callback_group
        callback = self.callback
        assert callback is not None
        if self._debug:
            callback = self._checked(callback)
        if self.raw:
            callback = _raw(callback)
        if self._wants_info:
            callback = _with_info(callback)
        handled = 0
        while True:
            if not queue:
                handled = 0
                await self._wait()
                continue
            msg = queue.popleft()
            if self._infos is not None:
                msg = self._take_info(msg)
                if msg is _EXPIRED:
                    continue
            if group.exclusive:
                self._busy += 1
                try:
                    await node._invoke(self, group, callback, msg)
                finally:
                    self._busy -= 1
                handled += 1
                if handled >= _BATCH:
                    handled = 0
                    await asyncio.sleep(0)
            else:
                self._busy += 1
                task = node._create_task(node._invoke(self, group, callback, msg), name=f"callback {self.topic_name}")
                task.add_done_callback(self._callback_done)

    def _callback_done(self, _task: asyncio.Task[None]) -> None:
        self._busy -= 1

    def _checked(self, callback: Callable[..., Any]) -> Callable[..., Any]:
        """``callback``, reporting when it changes the (shared) message it was given."""

        async def checked(msg: Any, *info: Any) -> Any:
            before = digest(msg)
            result = callback(msg, *info)
            if result is not None and inspect.isawaitable(result):
                result = await result
            if digest(msg) != before:
                self.node.get_logger().error(
                    f"debug_messages: the callback of subscription {self.topic_name} changed the message it "
                    "received; other subscribers share that object, so copy it before changing it",
                    throttle_duration_sec=1.0,
                )
            return result

        return checked

    def get_publisher_count(self) -> int:
        """How many publishers this subscription receives from (matched by type and QoS), as rclpy's."""
        runtime = self.node._runtime
        if runtime is None:
            return 0
        return sum(
            1
            for topic in runtime._bus.snapshot()
            if topic.name == self.topic_name
            for pub in topic.publishers
            if self in pub._subs
        )

    def destroy(self) -> None:
        self.node.destroy_subscription(self)


def _takes_message_info(callback: Callable[..., Any]) -> bool:
    """rclpy's rule (``Subscription.callback`` setter): a callback that can be called with one
    argument gets the message; else one callable with two gets ``(msg, MessageInfo)``; else
    ``RuntimeError``."""
    try:
        sig = inspect.signature(callback)
    except (TypeError, ValueError):
        return False
    try:
        sig.bind(object())
        return False
    except TypeError:
        pass
    try:
        sig.bind(object(), object())
        return True
    except TypeError:
        pass
    raise RuntimeError(
        "Subscription.__init__(): callback should be either be callable with one argument"
        "(to get only the message) or two (to get message and message info)"
    )


def _is_async(callback: Callable[..., Any]) -> bool:
    """Whether ``callback`` is a coroutine function (or an object whose ``__call__`` is one)."""
    return inspect.iscoroutinefunction(callback) or inspect.iscoroutinefunction(getattr(callback, "__call__", None))


def _with_info(callback: Callable[..., Any]) -> Callable[[tuple[Any, Any]], Any]:
    def with_info(pair: tuple[Any, Any]) -> Any:
        return callback(pair[0], pair[1])

    return with_info


def _raw(callback: Callable[..., Any]) -> Callable[..., Any]:
    """``create_subscription(raw=True)``: the callback gets the message's CDR bytes, as rclpy's."""
    from ..msgs import serialize

    def raw(msg: Any, *info: Any) -> Any:
        return callback(serialize(msg), *info)

    return raw


class MessageStream(Generic[M]):
    """``async for msg in node.subscribe(Type, "/topic")``: a subscription read as an async iterator.

    Also an async context manager; leaving it (or :meth:`close`) destroys the subscription.
    """

    def __init__(self, subscription: Subscription[M]) -> None:
        self.subscription = subscription

    def __repr__(self) -> str:
        return f"<MessageStream of {self.subscription!r}>"

    def __aiter__(self) -> MessageStream[M]:
        return self

    async def __anext__(self) -> M:
        sub = self.subscription
        while True:
            while not sub._queue:
                if sub.destroyed:
                    raise StopAsyncIteration
                await sub._wait()
            msg = sub._queue.popleft()
            if sub._infos is not None:
                msg = sub._take_info(msg)
                if msg is _EXPIRED:
                    continue
            return msg

    async def __aenter__(self) -> MessageStream[M]:
        return self

    async def __aexit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        if not self.subscription.destroyed:
            self.subscription.destroy()
