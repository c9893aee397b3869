"""``rclpy.topic_endpoint_info``: what ``Node.get_publishers_info_by_topic`` returns."""

from __future__ import annotations

import enum
from typing import Any

from .._missing import not_provided

__all__ = ["TopicEndpointInfo", "TopicEndpointTypeEnum"]


class TopicEndpointTypeEnum(enum.IntEnum):
    """rmw's endpoint kinds."""

    INVALID = 0
    PUBLISHER = 1
    SUBSCRIPTION = 2


class TopicEndpointInfo:
    """One publisher or subscription of a topic, as the graph sees it (rclpy's fields).

    ``endpoint_gid`` is not provided: aiorobot's graph does not carry rmw GIDs.
    """

    def __init__(
        self, node_name: str = "", node_namespace: str = "", topic_type: str = "", topic_type_hash: Any = None,
        endpoint_type: TopicEndpointTypeEnum = TopicEndpointTypeEnum.INVALID, qos_profile: Any = None,
    ) -> None:
        self.node_name = node_name
        self.node_namespace = node_namespace
        self.topic_type = topic_type
        self.topic_type_hash = topic_type_hash
        self.endpoint_type = endpoint_type
        self.qos_profile = qos_profile

    @property
    def endpoint_gid(self) -> list[int]:
        raise not_provided("rclpy.topic_endpoint_info.TopicEndpointInfo.endpoint_gid")

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, TopicEndpointInfo):
            return NotImplemented
        return all(getattr(self, k) == getattr(other, k) for k in
                   ("node_name", "node_namespace", "topic_type", "topic_type_hash", "endpoint_type", "qos_profile"))

    def __str__(self) -> str:
        return "\n".join([
            f"Node name: {self.node_name}",
            f"Node namespace: {self.node_namespace}",
            f"Topic type: {self.topic_type}",
            f"Topic type hash: {self.topic_type_hash}",
            f"Endpoint type: {self.endpoint_type.name}",
            f"QoS profile: {self.qos_profile}",
        ])


def endpoints_of(node: Any, topic_name: str, kind: str, no_mangle: bool) -> list[TopicEndpointInfo]:
    """The graph's publishers (``kind="publisher"``) or subscriptions of ``topic_name``, seen from ``node``."""
    if node.executor is None:  # not added to a runtime
        return []
    runtime = node.runtime
    topic = topic_name if no_mangle else node.resolve_topic_name(topic_name)
    graph = runtime.graph
    found = graph.publishers_of(topic) if kind == "publisher" else graph.subscriptions_of(topic)
    out = []
    for ep in found:
        namespace, _, name = ep.node.rpartition("/")
        out.append(TopicEndpointInfo(
            node_name=name, node_namespace=namespace or "/", topic_type=ep.type, topic_type_hash=_hash(ep.type),
            endpoint_type=TopicEndpointTypeEnum.PUBLISHER if kind == "publisher" else TopicEndpointTypeEnum.SUBSCRIPTION,
            qos_profile=ep.qos,
        ))
    return out


def _hash(type_name: str) -> str | None:
    from ...msgs import type_hash
    from ...msgs._registry import exists, get

    if not exists(type_name):
        return None
    return type_hash(get(type_name))
