"""The in-process bus: topics, endpoint matching by type and QoS, transient-local history.

Matching raises the QoS events of the endpoints concerned: ``incompatible_qos`` /
``incompatible_type`` for a pair that does not connect, ``matched`` (in
``Publisher._set_targets``) for each connection made or broken.

The bus is shared by both loops of a runtime, so registration happens under a
lock; the publish path reads an immutable tuple of matched subscriptions that
the bus replaces whenever the matching changes, so it takes no lock.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from ._errors import QoSIncompatibleError
from ._mutation import PublishGuard
from ._pubsub import Endpoint, Publisher, Subscription, Tap
from ._qos import DurabilityPolicy, QoSPolicyKind, incompatibility, incompatible_policy
from ._services import ServiceRegistry

if TYPE_CHECKING:
    from ._transport import Transport

__all__ = ["Bus", "Incompatibility"]

_log = logging.getLogger("aiorobot.runtime")

Sub = Subscription | Tap


@dataclass(frozen=True, slots=True)
class Incompatibility:
    """A publisher/subscription pair on one topic that does not connect, and why."""

    topic: str
    publisher: str
    subscription: str
    reason: str
    publisher_node: str = ""
    subscription_node: str = ""
    kind: str = "incompatible QoS"  # or "type mismatch"

    def __str__(self) -> str:
        return f"{self.kind} on {self.topic}: {self.publisher} does not connect to {self.subscription} ({self.reason})"


@dataclass
class _Topic:
    name: str
    publishers: list[Publisher] = field(default_factory=list)
    subscriptions: list[Sub] = field(default_factory=list)
    incompatible: list[tuple[Publisher, Sub, str]] = field(default_factory=list)


class Bus:
    """Connects the publishers and subscriptions of one runtime."""

    def __init__(self, *, strict_qos: bool = False, debug_messages: bool = False) -> None:
        self.strict_qos = strict_qos
        self.debug_messages = debug_messages
        self._lock = threading.RLock()
        self._topics: dict[str, _Topic] = {}
        self.services = ServiceRegistry()
        self.transport: Transport | None = None
        self._watchers: tuple[Callable[[Endpoint], None], ...] = ()

    def __repr__(self) -> str:
        return f"<Bus topics={len(self._topics)} strict_qos={self.strict_qos}>"

    # -- matching -----------------------------------------------------------------

    @staticmethod
    def _why_not(pub: Publisher, sub: Sub) -> str | None:
        if pub.type_name != sub.type_name:
            return f"publisher sends {pub.type_name}, subscription expects {sub.type_name}"
        return incompatibility(pub.qos, sub.qos)

    @staticmethod
    def _kind(pub: Publisher, sub: Sub) -> str:
        return "type mismatch" if pub.type_name != sub.type_name else "incompatible QoS"

    @classmethod
    def incompatibility(cls, pub: Publisher, sub: Sub, reason: str) -> Incompatibility:
        return Incompatibility(pub.topic_name, pub.describe(), sub.describe(), reason, pub.node_name,
                               sub.node_name, cls._kind(pub, sub))

    def _report(self, topic: _Topic, pub: Publisher, sub: Sub, reason: str) -> None:
        text = str(self.incompatibility(pub, sub, reason))
        if self.strict_qos:
            raise QoSIncompatibleError(text)
        _log.warning(text)

    def _check_strict(self, pairs: list[tuple[Publisher, Sub, str]], topic: _Topic) -> None:
        if self.strict_qos and pairs:
            pub, sub, reason = pairs[0]
            self._report(topic, pub, sub, reason)

    def add_publisher(self, pub: Publisher) -> None:
        self._add(pub)

    def add_subscription(self, sub: Sub) -> None:
        self._add(sub)

    def _add(self, endpoint: Publisher | Sub) -> None:
        """Register an endpoint: match it against the other side, warn or refuse what does not
        connect, and replay transient-local history to subscriptions it newly connects."""
        with self._lock:
            topic = self._topics.setdefault(endpoint.topic_name, _Topic(endpoint.topic_name))
            if isinstance(endpoint, Publisher):
                pairs = [(endpoint, s) for s in topic.subscriptions]
            else:
                pairs = [(p, endpoint) for p in topic.publishers]
            bad = [(p, s, r) for p, s in pairs if (r := self._why_not(p, s))]
            self._check_strict(bad, topic)
            if self.debug_messages:
                if isinstance(endpoint, Publisher):
                    endpoint._guard = PublishGuard()
                    endpoint._freeze = getattr(endpoint.msg_type, "_fz", None)  # read-only twins
                elif isinstance(endpoint, Subscription):
                    endpoint._debug = True
            if isinstance(endpoint, Publisher):
                topic.publishers.append(endpoint)
                retarget = [endpoint]
            else:
                topic.subscriptions.append(endpoint)
                retarget = topic.publishers
            for p, s, reason in bad:
                topic.incompatible.append((p, s, reason))
                self._report(topic, p, s, reason)
                self._raise_events(p, s)
            for pub in retarget:
                self._retarget(topic, pub)
            for p, s in pairs:
                if (
                    p._history is not None
                    and s in p._subs
                    and s.qos.durability is DurabilityPolicy.TRANSIENT_LOCAL
                ):
                    self._replay(p, s)
        self._notify_added(endpoint)

    @staticmethod
    def _raise_events(pub: Publisher, sub: Sub) -> None:
        """Count a pair that does not connect on both endpoints' incompatible QoS (with the
        policy) or incompatible type event handlers, as rmw does."""
        if pub.type_name != sub.type_name:
            name, policy = "incompatible_type", None
        else:
            found = incompatible_policy(pub.qos, sub.qos)
            name, policy = "incompatible_qos", found[0] if found is not None else QoSPolicyKind.INVALID
        for endpoint in (pub, sub):
            handler = getattr(endpoint, "_events", {}).get(name)
            if handler is not None:
                handler._fire(1, policy=policy)

    def remove(self, endpoint: Endpoint) -> None:
        with self._lock:
            topic = self._topics.get(endpoint.topic_name)
            if topic is None:
                return
            if isinstance(endpoint, Publisher):
                if endpoint in topic.publishers:
                    topic.publishers.remove(endpoint)
                endpoint._set_targets((), leaving=endpoint)
            elif endpoint in topic.subscriptions:
                topic.subscriptions.remove(endpoint)  # type: ignore[arg-type]
            topic.incompatible = [
                (p, s, r) for p, s, r in topic.incompatible if p is not endpoint and s is not endpoint
            ]
            for pub in topic.publishers:
                self._retarget(topic, pub, leaving=endpoint)
            if not topic.publishers and not topic.subscriptions:
                del self._topics[topic.name]
        if self.transport is not None:
            self.transport.endpoint_removed(endpoint)

    def watch(self, callback: Callable[[Endpoint], None]) -> Callable[[], None]:
        """Call ``callback(endpoint)`` for every endpoint added from now on, in the adding thread,
        before the adding call returns (so a recorder can tap a publisher before its first message).
        Returns the function that stops watching."""
        with self._lock:
            self._watchers = (*self._watchers, callback)

        def unwatch() -> None:
            with self._lock:
                self._watchers = tuple(w for w in self._watchers if w is not callback)

        return unwatch

    def _notify_added(self, endpoint: Endpoint) -> None:
        if self.transport is not None:
            self.transport.endpoint_added(endpoint)
        for watcher in self._watchers:
            watcher(endpoint)

    def _retarget(self, topic: _Topic, pub: Publisher, *, leaving: Endpoint | None = None) -> None:
        bad = {id(s) for p, s, _ in topic.incompatible if p is pub}
        pub._set_targets(tuple(s for s in topic.subscriptions if id(s) not in bad), leaving=leaving)

    @staticmethod
    def _replay(pub: Publisher, sub: Sub) -> None:
        """Hand a late-joining transient-local subscription the publisher's history, in order,
        leaving out messages whose lifespan has run out."""
        assert pub._history is not None
        now = pub.node._clock.now_ns() if pub._lifespan_ns is not None else 0
        for msg, meta in list(pub._history):
            if meta is not None and meta[2] is not None and now >= meta[2]:
                continue
            if isinstance(sub, Tap):
                sub._enqueue(msg)
            elif meta is None:
                sub.node._call_soon(sub._enqueue, msg)
            else:
                sub.node._call_soon(sub._deliver, msg, meta)

    def preview(
        self, publishers: Sequence[Publisher], subscriptions: Sequence[Sub]
    ) -> list[tuple[Publisher, Sub, str]]:
        """The pairs that would not connect if these endpoints joined, without registering them.

        Lets a runtime refuse a whole set of nodes under ``strict_qos`` before any starts.
        """
        with self._lock:
            pubs: dict[str, list[Publisher]] = {n: list(t.publishers) for n, t in self._topics.items()}
            subs: dict[str, list[Sub]] = {n: list(t.subscriptions) for n, t in self._topics.items()}
        new = {id(e) for e in (*publishers, *subscriptions)}
        for p in publishers:
            pubs.setdefault(p.topic_name, []).append(p)
        for s in subscriptions:
            subs.setdefault(s.topic_name, []).append(s)
        return [
            (p, s, reason)
            for topic, topic_pubs in pubs.items()
            for p in topic_pubs
            for s in subs.get(topic, [])
            if (id(p) in new or id(s) in new) and (reason := self._why_not(p, s))
        ]

    # -- introspection --------------------------------------------------------------

    def snapshot(self) -> list[_Topic]:
        """A consistent copy of every topic's endpoints (for ``Runtime.graph``)."""
        with self._lock:
            topics = [
                _Topic(
                    t.name,
                    [p for p in t.publishers if not _hidden(p)],
                    [s for s in t.subscriptions if not _hidden(s)],
                    [(p, s, r) for p, s, r in t.incompatible if not (_hidden(p) or _hidden(s))],
                )
                for t in sorted(self._topics.values(), key=lambda t: t.name)
            ]
        return [t for t in topics if t.publishers or t.subscriptions]

    def incompatibilities(self) -> list[Incompatibility]:
        with self._lock:
            return [
                self.incompatibility(p, s, r)
                for t in self._topics.values()
                for p, s, r in t.incompatible
                if not (_hidden(p) or _hidden(s))
            ]


def _hidden(endpoint: Endpoint) -> bool:
    """A transport's internal endpoint (its sender tap, its catch-all injector): not part of the graph."""
    return getattr(endpoint, "hidden", False)
