"""The graph queries of ``Node`` (rclpy's ``count_publishers`` and friends)."""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from ._runtime import Runtime

__all__ = ["NodeGraphMixin"]


class NodeGraphMixin:
    """Queries answered from ``runtime.graph``, with names resolved as the node resolves them."""

    if TYPE_CHECKING:  # provided by Node

        @property
        def runtime(self) -> Runtime: ...

        def resolve_topic_name(self, topic: str, *, kind: str = "topic") -> str: ...

    def count_publishers(self, topic: str) -> int:
        return len(self.runtime.graph.publishers_of(self.resolve_topic_name(topic)))

    def count_subscribers(self, topic: str) -> int:
        return len(self.runtime.graph.subscriptions_of(self.resolve_topic_name(topic)))

    def get_topic_names_and_types(self) -> list[tuple[str, list[str]]]:
        return [(t.name, list(t.types)) for t in self.runtime.graph.topics]
