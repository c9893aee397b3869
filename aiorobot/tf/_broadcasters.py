"""Publishing transforms on ``/tf`` and ``/tf_static``, as tf2_ros's broadcasters."""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

from aiorobot._core._qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

__all__ = [
    "DYNAMIC_QOS",
    "STATIC_QOS",
    "StaticTransformBroadcaster",
    "TransformBroadcaster",
]

# tf2_ros: DynamicBroadcasterQoS / DynamicListenerQoS and StaticBroadcasterQoS / StaticListenerQoS
DYNAMIC_QOS = QoSProfile(reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.VOLATILE, depth=100)
STATIC_QOS = QoSProfile(reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL, depth=1)


def _as_list(transforms: Any) -> list[Any]:
    if isinstance(transforms, Iterable) and not hasattr(transforms, "child_frame_id"):
        items = list(transforms)
    else:
        items = [transforms]
    for t in items:
        if getattr(t, "__msgtype__", None) != "geometry_msgs/msg/TransformStamped":
            raise TypeError(
                "expected a geometry_msgs/msg/TransformStamped or a list of them, got "
                f"{type(t).__name__}: {t!r}"
            )
    return items


class TransformBroadcaster:
    """Sends transforms on ``/tf`` (reliable, volatile, depth 100).

    Parameters
    ----------
    node
        The node that owns the publisher.
    topic
        Defaults to ``/tf``.
    """

    def __init__(self, node: Any, *, topic: str = "/tf", qos: QoSProfile = DYNAMIC_QOS) -> None:
        from aiorobot.msgs.tf2_msgs import TFMessage

        self._tf_message = TFMessage
        self._pub = node.create_publisher(TFMessage, topic, qos)

    def __repr__(self) -> str:
        return f"<TransformBroadcaster {self._pub.topic_name}>"

    def send_transform(self, transforms: Any) -> None:
        """Publish one ``TransformStamped`` or a list of them in one ``TFMessage``.

        The messages are handed to subscribers as they are: do not change them afterwards.
        """
        self._pub.publish(self._tf_message(transforms=_as_list(transforms)))


class StaticTransformBroadcaster:
    """Sends transforms that never change on ``/tf_static`` (transient local, depth 1).

    Every transform ever sent is kept, one per child frame (a newer one for the
    same child replaces it), and the whole set is republished on each send, so
    a late joiner receives all of them in the one message the topic keeps.
    """

    def __init__(self, node: Any, *, topic: str = "/tf_static", qos: QoSProfile = STATIC_QOS) -> None:
        from aiorobot.msgs.tf2_msgs import TFMessage

        self._tf_message = TFMessage
        self._pub = node.create_publisher(TFMessage, topic, qos)
        self._by_child: dict[str, Any] = {}

    def __repr__(self) -> str:
        return f"<StaticTransformBroadcaster {self._pub.topic_name} frames={len(self._by_child)}>"

    @property
    def transforms(self) -> list[Any]:
        """Every static transform sent so far, one per child frame."""
        return list(self._by_child.values())

    def send_transform(self, transforms: Any) -> None:
        """Add (or replace, by child frame) transforms and republish the whole set."""
        for t in _as_list(transforms):
            self._by_child[t.child_frame_id] = t
        self._pub.publish(self._tf_message(transforms=list(self._by_child.values())))
