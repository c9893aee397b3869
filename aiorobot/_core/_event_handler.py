"""QoS events, as rclpy's ``rclpy.event_handler``: deadline missed, liveliness, incompatible QoS
and type, message lost, matched.

``create_publisher(..., event_callbacks=PublisherEventCallbacks(deadline=cb))`` and
``create_subscription(..., event_callbacks=SubscriptionEventCallbacks(...))`` register
callbacks; each gets rclpy's status object (``total_count``, ``total_count_change``, ...).
Counts accumulate from the entity's creation and ``*_change`` is the change since the
callback last ran, so events that arrive while a callback is busy coalesce, as rmw's do.

What produces the events, in process:

- ``deadline``: a publisher with a finite ``QoSProfile.deadline`` that does not publish
  within one period after its previous message misses its offered deadline, once per
  period; a subscription likewise when no message arrives. As in DDS (rcl's
  ``test_events.cpp``) the first period starts at the first message.
- ``liveliness``: a ``MANUAL_BY_TOPIC`` publisher with a finite
  ``liveliness_lease_duration`` loses its liveliness when it neither publishes nor calls
  ``assert_liveliness()`` for one lease (``liveliness`` of the publisher, once per lapse);
  its subscriptions see ``alive_count`` go down and ``not_alive_count`` up, and the
  reverse when it asserts again. Matching and unmatching a publisher changes
  ``alive_count`` as well. ``AUTOMATIC`` publishers stay alive while they exist.
- ``incompatible_qos`` / ``incompatible_type``: raised by the bus's matching, the same
  check that logs (or, under ``strict_qos``, refuses) a pair that does not connect, with
  ``last_policy_kind`` naming the policy.
- ``message_lost``: a message a full KEEP_LAST queue dropped before the callback took it,
  or (reported by the zenoh transport) one that never arrived: a gap in its publisher's
  sequence numbers, as rmw_zenoh counts them.
- ``matched``: the bus connected or disconnected a peer endpoint (a compatible subscription
  for a publisher, a compatible publisher for a subscription; in process or, through a
  transport, remote). ``total_count`` counts connections ever made and ``current_count``
  those now, as rmw's ``rmw_matched_status_t``; an endpoint's own destruction or its node's
  removal does not report to itself.

Deadlines and leases are measured on the entity's node clock (sim time under
``use_sim_time``), and their watchers run on the loop of the node that owns the entity;
an entity with the default (infinite) deadline and lease has none.
"""

from __future__ import annotations

import asyncio
import enum
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from ._clock import ClockJump
from ._qos import QoSPolicyKind

if TYPE_CHECKING:
    from ._groups import CallbackGroup
    from ._node import Node

__all__ = [
    "EventHandler",
    "IncompatibleTypeInfo",
    "PublisherEventCallbacks",
    "QoSLivelinessChangedInfo",
    "QoSLivelinessLostInfo",
    "QoSMessageLostInfo",
    "QoSOfferedDeadlineMissedInfo",
    "QoSOfferedIncompatibleQoSInfo",
    "QoSPublisherEventType",
    "QoSPublisherMatchedInfo",
    "QoSRequestedDeadlineMissedInfo",
    "QoSRequestedIncompatibleQoSInfo",
    "QoSSubscriptionEventType",
    "QoSSubscriptionMatchedInfo",
    "SubscriptionEventCallbacks",
]


@dataclass(frozen=True, slots=True)
class QoSRequestedDeadlineMissedInfo:
    """A subscription missed its requested deadline (rmw's ``rmw_requested_deadline_missed_status_t``)."""

    total_count: int = 0
    total_count_change: int = 0


@dataclass(frozen=True, slots=True)
class QoSOfferedDeadlineMissedInfo:
    """A publisher missed its offered deadline (rmw's ``rmw_offered_deadline_missed_status_t``)."""

    total_count: int = 0
    total_count_change: int = 0


@dataclass(frozen=True, slots=True)
class QoSLivelinessChangedInfo:
    """The liveliness of a subscription's publishers changed (``rmw_liveliness_changed_status_t``)."""

    alive_count: int = 0
    not_alive_count: int = 0
    alive_count_change: int = 0
    not_alive_count_change: int = 0


@dataclass(frozen=True, slots=True)
class QoSLivelinessLostInfo:
    """A publisher failed to assert its liveliness within its lease (``rmw_liveliness_lost_status_t``)."""

    total_count: int = 0
    total_count_change: int = 0


@dataclass(frozen=True, slots=True)
class QoSMessageLostInfo:
    """Messages a subscription lost (``rmw_message_lost_status_t``)."""

    total_count: int = 0
    total_count_change: int = 0


@dataclass(frozen=True, slots=True)
class QoSRequestedIncompatibleQoSInfo:
    """An endpoint on the topic requests or offers an incompatible QoS (``rmw_qos_incompatible_event_status_t``)."""

    total_count: int = 0
    total_count_change: int = 0
    last_policy_kind: QoSPolicyKind = QoSPolicyKind.INVALID


#: rclpy's alias: publishers get the same status type.
QoSOfferedIncompatibleQoSInfo = QoSRequestedIncompatibleQoSInfo


@dataclass(frozen=True, slots=True)
class IncompatibleTypeInfo:
    """An endpoint on the topic has another message type (``rmw_incompatible_type_status_t``)."""

    total_count: int = 0
    total_count_change: int = 0


@dataclass(frozen=True, slots=True)
class QoSPublisherMatchedInfo:
    """Peer endpoints connected to or disconnected from this one (rmw's ``rmw_matched_status_t``).

    ``total_count``: connections ever made; ``current_count``: connected now; each
    ``*_change``: the change since the callback last ran.
    """

    total_count: int = 0
    total_count_change: int = 0
    current_count: int = 0
    current_count_change: int = 0


#: rclpy's alias: subscriptions get the same status type.
QoSSubscriptionMatchedInfo = QoSPublisherMatchedInfo


class QoSPublisherEventType(enum.IntEnum):
    """rcl's ``rcl_publisher_event_type_t`` values."""

    RCL_PUBLISHER_OFFERED_DEADLINE_MISSED = 0
    RCL_PUBLISHER_LIVELINESS_LOST = 1
    RCL_PUBLISHER_OFFERED_INCOMPATIBLE_QOS = 2
    RCL_PUBLISHER_INCOMPATIBLE_TYPE = 3
    RCL_PUBLISHER_MATCHED = 4


class QoSSubscriptionEventType(enum.IntEnum):
    """rcl's ``rcl_subscription_event_type_t`` values."""

    RCL_SUBSCRIPTION_REQUESTED_DEADLINE_MISSED = 0
    RCL_SUBSCRIPTION_LIVELINESS_CHANGED = 1
    RCL_SUBSCRIPTION_REQUESTED_INCOMPATIBLE_QOS = 2
    RCL_SUBSCRIPTION_MESSAGE_LOST = 3
    RCL_SUBSCRIPTION_INCOMPATIBLE_TYPE = 4
    RCL_SUBSCRIPTION_MATCHED = 5


# event name -> (event type, status type)
_PUBLISHER_EVENTS: dict[str, tuple[enum.IntEnum, type]] = {
    "deadline": (QoSPublisherEventType.RCL_PUBLISHER_OFFERED_DEADLINE_MISSED, QoSOfferedDeadlineMissedInfo),
    "liveliness": (QoSPublisherEventType.RCL_PUBLISHER_LIVELINESS_LOST, QoSLivelinessLostInfo),
    "incompatible_qos": (QoSPublisherEventType.RCL_PUBLISHER_OFFERED_INCOMPATIBLE_QOS, QoSOfferedIncompatibleQoSInfo),
    "incompatible_type": (QoSPublisherEventType.RCL_PUBLISHER_INCOMPATIBLE_TYPE, IncompatibleTypeInfo),
    "matched": (QoSPublisherEventType.RCL_PUBLISHER_MATCHED, QoSPublisherMatchedInfo),
}
_SUBSCRIPTION_EVENTS: dict[str, tuple[enum.IntEnum, type]] = {
    "deadline": (QoSSubscriptionEventType.RCL_SUBSCRIPTION_REQUESTED_DEADLINE_MISSED, QoSRequestedDeadlineMissedInfo),
    "incompatible_qos": (
        QoSSubscriptionEventType.RCL_SUBSCRIPTION_REQUESTED_INCOMPATIBLE_QOS,
        QoSRequestedIncompatibleQoSInfo,
    ),
    "liveliness": (QoSSubscriptionEventType.RCL_SUBSCRIPTION_LIVELINESS_CHANGED, QoSLivelinessChangedInfo),
    "message_lost": (QoSSubscriptionEventType.RCL_SUBSCRIPTION_MESSAGE_LOST, QoSMessageLostInfo),
    "incompatible_type": (QoSSubscriptionEventType.RCL_SUBSCRIPTION_INCOMPATIBLE_TYPE, IncompatibleTypeInfo),
    "matched": (QoSSubscriptionEventType.RCL_SUBSCRIPTION_MATCHED, QoSSubscriptionMatchedInfo),
}


class EventHandler:
    """One QoS event callback of a publisher or subscription (rclpy's ``EventHandler``).

    Built by :class:`PublisherEventCallbacks` / :class:`SubscriptionEventCallbacks`; the
    entity lists its handlers in ``event_handlers``. The callback runs on the owning
    node's loop under ``callback_group``. ``take_event()`` returns the status now.

    rclpy difference: deadlines and liveliness leases are measured on the node clock, so
    under ``use_sim_time`` they follow ``/clock`` (DDS measures them on the wall clock); and
    ``message_lost`` counts messages a full KEEP_LAST queue dropped before the callback
    took them (DDS counts samples lost in transit, which an in-process bus never loses).
    """

    def __init__(
        self, *, callback_group: CallbackGroup, callback: Callable[[Any], Any], event_type: enum.IntEnum,
        info_type: type, parent: Any,
    ) -> None:
        self.callback_group = callback_group
        self.callback = callback
        self.event_type = event_type
        self._info_type = info_type
        self._parent = parent
        self._counts = [0] * len(_count_fields(info_type))
        self._changes = [0] * len(self._counts)
        self._policy = QoSPolicyKind.INVALID
        self._pending = False
        self._task: asyncio.Task[None] | None = None

    def __repr__(self) -> str:
        return f"<EventHandler {self.event_type.name} of {self._parent!r}>"

    def _fire(self, *deltas: int, policy: QoSPolicyKind | None = None) -> None:
        """Count an event (from any thread); the callback runs soon on the owner's loop."""
        self._parent.node._call_soon(self._count, deltas, policy)

    def _count(self, deltas: tuple[int, ...], policy: QoSPolicyKind | None) -> None:
        if self._parent.destroyed:
            return
        for i, delta in enumerate(deltas):
            self._counts[i] += delta
            self._changes[i] += delta
        if policy is not None:
            self._policy = policy
        node: Node = self._parent.node
        if self._pending and self._task is not None and self._task.done():
            self._pending = False  # its delivery was cancelled before it ran (its node stopped)
        if not self._pending and node._loop is not None:
            self._pending = True
            self._task = node._create_task(self._deliver(), name=f"event {self.event_type.name} {self._parent.topic_name}")

    def take_event(self) -> Any:
        """The status now (counts, and changes since the last take, which this resets)."""
        fields = _count_fields(self._info_type)
        values: dict[str, Any] = {}
        for name, count, change in zip(fields, self._counts, self._changes):
            values[name] = count
            values[f"{name}_change"] = change
        if self._info_type is QoSRequestedIncompatibleQoSInfo:
            values["last_policy_kind"] = self._policy
        self._changes = [0] * len(self._counts)
        return self._info_type(**values)

    async def _deliver(self) -> None:
        self._pending = False
        if self._parent.destroyed:
            return
        node: Node = self._parent.node
        await node._invoke(self, self.callback_group, self.callback, self.take_event())


def _count_fields(info_type: type) -> tuple[str, ...]:
    if info_type is QoSLivelinessChangedInfo:
        return ("alive_count", "not_alive_count")
    if info_type is QoSPublisherMatchedInfo:
        return ("total_count", "current_count")
    return ("total_count",)


class _EventCallbacks:
    _events: dict[str, tuple[enum.IntEnum, type]] = {}

    def __init__(self, use_default_callbacks: bool, **callbacks: Callable[[Any], Any] | None) -> None:
        for name, callback in callbacks.items():
            setattr(self, name, callback)
        self.use_default_callbacks = use_default_callbacks

    def __repr__(self) -> str:
        given = [name for name in self._events if getattr(self, name, None) is not None]
        return f"<{type(self).__name__} {', '.join(given) or 'none'}>"

    def create_event_handlers(self, callback_group: CallbackGroup, parent: Any) -> dict[str, EventHandler]:
        handlers: dict[str, EventHandler] = {}
        for name, (event_type, info_type) in self._events.items():
            callback = getattr(self, name, None)
            if callback is None:
                continue
            if not callable(callback):
                raise TypeError(f"{type(self).__name__}.{name}: expected a callable, found {callback!r}")
            handlers[name] = EventHandler(
                callback_group=callback_group, callback=callback, event_type=event_type, info_type=info_type,
                parent=parent,
            )
        return handlers


class SubscriptionEventCallbacks(_EventCallbacks):
    """The QoS event callbacks of a subscription (rclpy's), for ``create_subscription(event_callbacks=)``.

    rclpy difference: no default incompatible-QoS and incompatible-type handlers
    (``use_default_callbacks`` is accepted and has no effect): the runtime already logs one
    warning naming both endpoints of a pair that does not connect.
    """

    _events = _SUBSCRIPTION_EVENTS

    def __init__(
        self,
        *,
        deadline: Callable[[QoSRequestedDeadlineMissedInfo], Any] | None = None,
        incompatible_qos: Callable[[QoSRequestedIncompatibleQoSInfo], Any] | None = None,
        liveliness: Callable[[QoSLivelinessChangedInfo], Any] | None = None,
        message_lost: Callable[[QoSMessageLostInfo], Any] | None = None,
        incompatible_type: Callable[[IncompatibleTypeInfo], Any] | None = None,
        matched: Callable[[QoSSubscriptionMatchedInfo], Any] | None = None,
        use_default_callbacks: bool = True,
    ) -> None:
        super().__init__(
            use_default_callbacks, deadline=deadline, incompatible_qos=incompatible_qos, liveliness=liveliness,
            message_lost=message_lost, incompatible_type=incompatible_type, matched=matched,
        )


class PublisherEventCallbacks(_EventCallbacks):
    """The QoS event callbacks of a publisher (rclpy's), for ``create_publisher(event_callbacks=)``.

    rclpy difference: no default incompatible-QoS and incompatible-type handlers
    (``use_default_callbacks`` is accepted and has no effect): the runtime already logs one
    warning naming both endpoints of a pair that does not connect.
    """

    _events = _PUBLISHER_EVENTS

    def __init__(
        self,
        *,
        deadline: Callable[[QoSOfferedDeadlineMissedInfo], Any] | None = None,
        liveliness: Callable[[QoSLivelinessLostInfo], Any] | None = None,
        incompatible_qos: Callable[[QoSOfferedIncompatibleQoSInfo], Any] | None = None,
        incompatible_type: Callable[[IncompatibleTypeInfo], Any] | None = None,
        matched: Callable[[QoSPublisherMatchedInfo], Any] | None = None,
        use_default_callbacks: bool = True,
    ) -> None:
        super().__init__(
            use_default_callbacks, deadline=deadline, liveliness=liveliness, incompatible_qos=incompatible_qos,
            incompatible_type=incompatible_type, matched=matched,
        )


class Lease:
    """Calls ``on_expire()`` when ``period_ns`` passes on the node clock without a :meth:`touch`.

    ``repeat``: expire once per period until touched again (deadlines); otherwise once
    per lapse (liveliness). Runs as one task on the owner node's loop, started by
    :meth:`start`; idle (awaiting a touch) until the first touch.
    """

    def __init__(self, node: Node, period_ns: int, on_expire: Callable[[], None], *, repeat: bool) -> None:
        self.node = node
        self.period_ns = period_ns
        self.on_expire = on_expire
        self.repeat = repeat
        self._last: int | None = None
        self._idle = False
        self._wake: asyncio.Future[None] | None = None
        self._task: asyncio.Task[None] | None = None

    def touch(self) -> None:
        """Restart the period now (any thread)."""
        self._last = self.node._clock.now_ns()
        if self._idle:
            self.node._call_soon(self._resume)

    def _resume(self) -> None:
        wake = self._wake
        if wake is not None and not wake.done():
            wake.set_result(None)

    def start(self) -> None:
        """Start watching (on the node's loop)."""
        if self._task is None:
            self._task = self.node._create_task(self._run(), name="qos lease")

    def stop(self) -> None:
        if self._task is not None:
            self._task.cancel()
            self._task = None

    async def _run(self) -> None:
        node = self.node
        loop = asyncio.get_running_loop()
        while True:
            last = self._last
            if last is None:
                self._wake = loop.create_future()
                self._idle = True
                try:
                    if self._last is None:
                        await self._wake
                finally:
                    self._idle = False
                    self._wake = None
                continue
            due = last + self.period_ns
            clock = node._clock
            try:
                if clock.use_sim_time:
                    await clock.sleep_until_ns(due)
                else:
                    await asyncio.sleep(max(0.0, (due - clock.now_ns()) / 1e9))
            except ClockJump:  # time jumped back or its source changed: start the period again
                if self._last is not None:
                    self._last = node._clock.now_ns()
                continue
            if self._last != last or node._clock.now_ns() < due:
                continue  # touched meanwhile, or woke early
            self._last = due if self.repeat else None
            self.on_expire()
