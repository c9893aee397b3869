"""Runtime statistics: what every callback costs, and ``~/get_statistics`` to read them remotely.

Recording (always on, cheap): ``Node._invoke`` and the service dispatcher time each
callback with two ``time.monotonic_ns()`` reads and hand the duration to the entity's
:class:`CallbackRecorder` (a count, a maximum and a ring of the last
:data:`WINDOW` durations; about 0.3 us a callback). Subscriptions already count what
they received and dropped, publishers what they published, timers their lateness
(``Timer.statistics()``), the watchdog the stalls and the culprit watch the late
priority periods; nothing else runs until somebody asks.

Reading: :func:`node_statistics` turns one node's figures (and its process's) into
plain data; every node that has parameter services also serves it as JSON on
``~/get_statistics`` (``std_srvs/srv/Trigger``: ``success`` and the JSON document in
``message``), which ``aiorobot top`` calls on every node of the graph. Counts are
totals since the start; rates (callbacks/s, messages/s, CPU %) are the reader's
differences between two answers (each carries ``monotonic_sec`` and the process's
``cpu_sec``). The document's layout is in docs/observability.md.
"""

from __future__ import annotations

import json
import os
import socket
import threading
import time
from collections import deque
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from ._timer import _percentile

if TYPE_CHECKING:
    from ._node import Node

__all__ = [
    "SCHEMA",
    "WINDOW",
    "CallbackRecorder",
    "CallbackStatistics",
    "create_statistics_service",
    "describe_entity",
    "node_statistics",
    "process_statistics",
]

#: how many recent callback durations an entity keeps for its percentiles
WINDOW = 1024
#: the version of the ``~/get_statistics`` document (bumped when a field changes meaning)
SCHEMA = 1


@dataclass(frozen=True, slots=True)
class CallbackStatistics:
    """One entity's callbacks: how many ran, and their durations over the last :data:`WINDOW`."""

    calls: int
    time_p50_sec: float
    time_p99_sec: float
    time_max_sec: float


class CallbackRecorder:
    """Durations of one entity's callbacks (recorded on its node's loop)."""

    __slots__ = ("calls", "max_ns", "recent")

    def __init__(self) -> None:
        self.calls = 0
        self.max_ns = 0
        self.recent: deque[int] = deque(maxlen=WINDOW)

    def add(self, duration_ns: int) -> None:
        self.calls += 1
        self.recent.append(duration_ns)
        if duration_ns > self.max_ns:
            self.max_ns = duration_ns

    def statistics(self) -> CallbackStatistics:
        recent = sorted(list(self.recent))  # list() first: another thread may append meanwhile
        return CallbackStatistics(
            calls=self.calls,
            time_p50_sec=_percentile(recent, 0.5) / 1e9,
            time_p99_sec=_percentile(recent, 0.99) / 1e9,
            time_max_sec=self.max_ns / 1e9,
        )


def describe_entity(entity: Any) -> tuple[str, str]:
    """``(kind, name)`` of a callback's entity: ``("timer", "0.02s")``, ``("subscription", "/scan")``."""
    from ._pubsub import Subscription
    from ._services import Service
    from ._timer import Timer

    if isinstance(entity, Timer):
        return "timer", f"{entity.period_ns / 1e9:g}s"
    if isinstance(entity, Subscription):
        return "subscription", entity.topic_name
    if isinstance(entity, Service):
        return "service", entity.srv_name
    return type(entity).__name__.lower(), getattr(entity, "topic_name", "") or getattr(entity, "srv_name", "") or ""


def _ms(sec: float) -> float:
    return round(sec * 1000.0, 4)


def _callbacks(node: Node, entity: Any) -> dict[str, Any]:
    recorder = node._callback_stats.get(entity)
    stats = recorder.statistics() if recorder is not None else CallbackStatistics(0, 0.0, 0.0, 0.0)
    return {
        "callbacks": stats.calls,
        "time_p50_ms": _ms(stats.time_p50_sec),
        "time_p99_ms": _ms(stats.time_p99_sec),
        "time_max_ms": _ms(stats.time_max_sec),
    }


def node_statistics(node: Node) -> dict[str, Any]:
    """One node's figures as plain data (the ``node`` part of the ``~/get_statistics`` document)."""
    entities: list[dict[str, Any]] = []
    for timer in node.timers:
        t = timer.statistics()
        entities.append({
            "kind": "timer", "name": f"{timer.period_ns / 1e9:g}s", **_callbacks(node, timer),
            "lateness_p50_ms": _ms(t.lateness_p50_sec), "lateness_p99_ms": _ms(t.lateness_p99_sec),
            "lateness_max_ms": _ms(t.lateness_max_sec), "overruns": t.overruns,
        })
    for sub in node.subscriptions:
        entities.append({
            "kind": "subscription", "name": sub.topic_name, "type": sub.type_name, **_callbacks(node, sub),
            "received": sub.received, "dropped": sub.dropped, "queued": sub.queued, "depth": sub.qos.depth,
        })
    for service in node.services:
        entities.append({"kind": "service", "name": service.srv_name, **_callbacks(node, service)})
    known = {id(e) for e in (*node.timers, *node.subscriptions, *node.services)}
    for entity, recorder in list(node._callback_stats.items()):
        if id(entity) not in known:  # event handlers, action clients' feedback, lowlevel.run_callback
            kind, name = describe_entity(entity)
            entities.append({"kind": kind, "name": name, **_callbacks(node, entity)})
    publishers = [
        {"topic": p.topic_name, "type": p.type_name, "published": p.published} for p in node.publishers
    ]
    runtime = node._runtime
    stalls = failures = 0
    if runtime is not None:
        stats = runtime.statistics()
        fqn = node.get_fully_qualified_name()
        stalls = sum(n for (_, who, _), n in stats["stalls"].items() if who == fqn)
        failures = sum(n for (who, _), n in stats["failures"].items() if who == fqn)
    return {
        "name": node.get_fully_qualified_name(),
        "executor": node.executor or "",
        "entities": entities,
        "publishers": publishers,
        "stalls": stalls,
        "failures": failures,
    }


def process_statistics(runtime: Any) -> dict[str, Any]:
    """The process part of the document: identity, CPU time, the late-period culprits."""
    watch = runtime.late_watch
    return {
        "pid": os.getpid(),
        "host": socket.gethostname(),
        "cpu_sec": time.process_time(),
        "monotonic_sec": time.monotonic(),
        "threads": threading.active_count(),
        "nodes": len(runtime.nodes),
        "late_threshold_ms": _ms(runtime.late_threshold) if runtime.late_threshold is not None else None,
        "late_periods": watch.late_periods if watch is not None else 0,
        "culprits": [c.as_dict() for c in watch.culprits()] if watch is not None else [],
    }


def create_statistics_service(node: Node) -> Any:
    """Serve ``~/get_statistics`` (``std_srvs/srv/Trigger``, the JSON document in ``message``)."""
    from ..msgs.std_srvs import Trigger

    def answer(_request: Any) -> Any:
        runtime = node._runtime
        if runtime is None:  # a call cannot reach a node outside a runtime; kept for direct calls
            return Trigger.Response(success=False, message="the node is not added to a runtime")
        doc = {"schema": SCHEMA, "process": process_statistics(runtime), "node": node_statistics(node)}
        return Trigger.Response(success=True, message=json.dumps(doc, separators=(",", ":")))

    return node.create_service(Trigger, "~/get_statistics", answer)
