"""The graph queries of ``Node`` (rclpy's ``count_publishers``, ``get_node_names`` and friends)."""

from __future__ import annotations

import asyncio
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from ._graph import ServiceInfo
    from ._runtime import Runtime

__all__ = ["NodeGraphMixin", "NodeNameNonExistentError"]


class NodeNameNonExistentError(RuntimeError):
    """A graph query named a node that is not in the graph (rclpy's ``NodeNameNonExistentError``)."""

#: How often ``wait_for_node`` looks at the graph again, in seconds.
_WAIT_FOR_NODE_POLL_SEC = 0.01


def _check_str(value: object, what: str) -> str:
    if not isinstance(value, str):
        raise TypeError(f"{what} must be a str, got {value!r}")
    return value


def _fully_qualified(node_name: str, node_namespace: str) -> str:
    namespace = node_namespace if node_namespace.startswith("/") else "/" + node_namespace
    return namespace.rstrip("/") + "/" + node_name


class NodeGraphMixin:
    """Queries answered from ``runtime.graph``, with names resolved as the node resolves them."""

    if TYPE_CHECKING:  # provided by Node

        @property
        def runtime(self) -> Runtime: ...

        def resolve_topic_name(self, topic: str, *, kind: str = "topic") -> str: ...

        async def _wait_with_timeout(self, aw: object, timeout_sec: float | None) -> object: ...

    # -- topics ---------------------------------------------------------------------

    def count_publishers(self, topic: str) -> int:
        return len(self.runtime.graph.publishers_of(self.resolve_topic_name(topic)))

    def count_subscribers(self, topic: str) -> int:
        return len(self.runtime.graph.subscriptions_of(self.resolve_topic_name(topic)))

    def get_topic_names_and_types(self) -> list[tuple[str, list[str]]]:
        return [(t.name, list(t.types)) for t in self.runtime.graph.topics]

    def get_publisher_names_and_types_by_node(self, node_name: str, node_namespace: str) -> list[tuple[str, list[str]]]:
        """Topics the node ``node_namespace/node_name`` publishes, with their types."""
        fqn = self._existing_node(node_name, node_namespace)
        return self._topics_of(fqn, publishers=True)

    def get_subscriber_names_and_types_by_node(self, node_name: str, node_namespace: str) -> list[tuple[str, list[str]]]:
        """Topics the node ``node_namespace/node_name`` subscribes to, with their types."""
        fqn = self._existing_node(node_name, node_namespace)
        return self._topics_of(fqn, publishers=False)

    def _topics_of(self, fqn: str, *, publishers: bool) -> list[tuple[str, list[str]]]:
        out = []
        for t in self.runtime.graph.topics:
            endpoints = t.publishers if publishers else t.subscriptions
            types = sorted({e.type for e in endpoints if e.node == fqn})
            if types:
                out.append((t.name, types))
        return out

    # -- services -------------------------------------------------------------------

    def count_services(self, service_name: str) -> int:
        """How many servers offer ``service_name`` (resolved as this node resolves it)."""
        return len(self._service(service_name, "service_name").servers)

    def count_clients(self, service_name: str) -> int:
        """How many clients of ``service_name`` exist (resolved as this node resolves it)."""
        return len(self._service(service_name, "service_name").clients)

    def _service(self, service_name: str, what: str) -> ServiceInfo:
        from ._graph import ServiceInfo

        name = self.resolve_topic_name(_check_str(service_name, what), kind="service")
        for s in self.runtime.graph.services:
            if s.name == name:
                return s
        return ServiceInfo(name, (), (), ())

    def get_service_names_and_types(self) -> list[tuple[str, list[str]]]:
        """Every service with its types (action services under ``<action>/_action/`` included, as rclpy)."""
        return [(s.name, list(s.types)) for s in self.runtime.graph.services if s.servers]

    def get_service_names_and_types_by_node(self, node_name: str, node_namespace: str) -> list[tuple[str, list[str]]]:
        """Services the node ``node_namespace/node_name`` serves, with their types.

        Raises ``NodeNameNonExistentError`` when there is no such node (as rclpy).
        """
        fqn = self._existing_node(node_name, node_namespace)
        return [(s.name, list(s.types)) for s in self.runtime.graph.services if fqn in s.servers]

    def get_client_names_and_types_by_node(self, node_name: str, node_namespace: str) -> list[tuple[str, list[str]]]:
        """Services the node ``node_namespace/node_name`` has clients of, with their types."""
        fqn = self._existing_node(node_name, node_namespace)
        return [(s.name, list(s.types)) for s in self.runtime.graph.services if fqn in s.clients]

    # -- nodes ----------------------------------------------------------------------

    def get_node_names(self) -> list[str]:
        """The names (without namespace) of every node in the graph."""
        return [n.name for n in self.runtime.graph.nodes]

    def get_node_names_and_namespaces(self) -> list[tuple[str, str]]:
        """``(name, namespace)`` of every node in the graph (the root namespace is ``"/"``)."""
        return [(n.name, n.namespace or "/") for n in self.runtime.graph.nodes]

    def get_node_names_and_namespaces_with_enclaves(self) -> list[tuple[str, str, str]]:
        """``(name, namespace, enclave)`` of every node; aiorobot has no security enclaves, so ``"/"``."""
        return [(name, namespace, "/") for name, namespace in self.get_node_names_and_namespaces()]

    def get_fully_qualified_node_names(self) -> list[str]:
        return [n.fully_qualified_name for n in self.runtime.graph.nodes]

    def _existing_node(self, node_name: str, node_namespace: str) -> str:
        fqn = _fully_qualified(_check_str(node_name, "node_name"), _check_str(node_namespace, "node_namespace"))
        if fqn not in self.get_fully_qualified_node_names():
            raise NodeNameNonExistentError(f"cannot get information of node {fqn!r}: it does not exist in the graph")
        return fqn

    async def wait_for_node(self, fully_qualified_node_name: str, timeout_sec: float) -> bool:
        """True once a node of that name is in the graph; False after ``timeout_sec`` (node clock).

        A name without a leading ``/`` is taken from the root namespace, as rclpy does.

        rclpy difference: a coroutine (``await node.wait_for_node(...)``) rather than a
        call that blocks the thread, so the node keeps running while it waits.
        """
        name = _check_str(fully_qualified_node_name, "fully_qualified_node_name")
        if not name.startswith("/"):
            name = "/" + name

        async def appear() -> None:
            while name not in self.get_fully_qualified_node_names():
                await asyncio.sleep(_WAIT_FOR_NODE_POLL_SEC)

        try:
            await self._wait_with_timeout(appear(), timeout_sec)
        except TimeoutError:
            return False
        return True
