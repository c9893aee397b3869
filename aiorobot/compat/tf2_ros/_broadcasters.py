"""tf2_ros's ``TransformBroadcaster`` and ``StaticTransformBroadcaster`` over aiorobot.tf's."""

from __future__ import annotations

from typing import Any

from ... import tf as _tf
from ..._core._qos import DurabilityPolicy, HistoryPolicy, QoSProfile

__all__ = ["StaticTransformBroadcaster", "TransformBroadcaster"]


class TransformBroadcaster(_tf.TransformBroadcaster):
    """Sends transforms on ``/tf`` (``qos`` defaults to depth 100, reliable, volatile)."""

    def __init__(self, node: Any, qos: QoSProfile | int | None = None) -> None:
        super().__init__(node, qos=QoSProfile(depth=100) if qos is None else qos)  # type: ignore[arg-type]
        self.pub_tf = self._pub

    def sendTransform(self, transform: Any) -> None:  # noqa: N802 - tf2_ros's name
        """Publish a ``TransformStamped`` or a list of them in one ``TFMessage``."""
        self.send_transform(transform)


class StaticTransformBroadcaster(_tf.StaticTransformBroadcaster):
    """Sends transforms on ``/tf_static`` (transient local, depth 1); every send republishes the whole set.

    rclpy difference: a transform for a child frame already sent replaces the earlier one, as
    tf2_ros's C++ StaticTransformBroadcaster does; tf2_ros's Python one keeps the first and
    silently drops the update.
    """

    def __init__(self, node: Any, qos: QoSProfile | int | None = None) -> None:
        if qos is None:
            qos = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL, history=HistoryPolicy.KEEP_LAST)
        super().__init__(node, qos=qos)  # type: ignore[arg-type]
        self.pub_tf = self._pub

    def sendTransform(self, transform: Any) -> None:  # noqa: N802 - tf2_ros's name
        """Add transforms (a newer one for a child frame replaces the older) and republish them all."""
        self.send_transform(transform)
