"""Introspection of a runtime's graph: nodes, topics, endpoints with QoS, incompatibilities."""

from __future__ import annotations

from dataclasses import dataclass, field

from ._bus import Incompatibility
from ._qos import QoSProfile

__all__ = ["EndpointInfo", "Graph", "NodeInfo", "ServiceInfo", "TopicInfo"]


@dataclass(frozen=True, slots=True)
class NodeInfo:
    name: str
    namespace: str
    fully_qualified_name: str
    executor: str


@dataclass(frozen=True, slots=True)
class EndpointInfo:
    node: str
    topic: str
    type: str
    kind: str  # "publisher" | "subscription"
    qos: QoSProfile


@dataclass(frozen=True, slots=True)
class TopicInfo:
    name: str
    types: tuple[str, ...]
    publishers: tuple[EndpointInfo, ...]
    subscriptions: tuple[EndpointInfo, ...]


@dataclass(frozen=True, slots=True)
class ServiceInfo:
    name: str
    types: tuple[str, ...]
    servers: tuple[str, ...]
    clients: tuple[str, ...]


@dataclass(frozen=True)
class Graph:
    """A snapshot of the graph (``Runtime.graph``)."""

    nodes: tuple[NodeInfo, ...]
    topics: tuple[TopicInfo, ...]
    incompatible_qos: tuple[Incompatibility, ...]
    services: tuple[ServiceInfo, ...] = field(default=())
    actions: tuple[ServiceInfo, ...] = field(default=())

    def topic(self, name: str) -> TopicInfo | None:
        return next((t for t in self.topics if t.name == name), None)

    def node(self, name: str) -> NodeInfo | None:
        return next((n for n in self.nodes if name in (n.fully_qualified_name, n.name)), None)

    def publishers_of(self, topic: str) -> tuple[EndpointInfo, ...]:
        info = self.topic(topic)
        return info.publishers if info else ()

    def subscriptions_of(self, topic: str) -> tuple[EndpointInfo, ...]:
        info = self.topic(topic)
        return info.subscriptions if info else ()

    def to_dot(self) -> str:
        """Graphviz text: nodes as boxes, topics as ellipses, edges publisher -> topic -> subscriber."""
        lines = ["digraph aiorobot {", "  rankdir=LR;"]
        for n in self.nodes:
            lines.append(f'  "{n.fully_qualified_name}" [shape=box];')
        bad = {(i.topic) for i in self.incompatible_qos}
        for t in self.topics:
            style = ", color=red" if t.name in bad else ""
            lines.append(f'  "{t.name}" [shape=ellipse, label="{t.name}\\n{" | ".join(t.types)}"{style}];')
            for p in t.publishers:
                lines.append(f'  "{p.node}" -> "{t.name}";')
            for s in t.subscriptions:
                lines.append(f'  "{t.name}" -> "{s.node}";')
        lines.append("}")
        return "\n".join(lines) + "\n"
