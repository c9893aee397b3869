"""tf2_ros's ``TransformListener``: ``/tf`` and ``/tf_static`` into a buffer."""

from __future__ import annotations

from typing import Any

from ..._core._groups import ReentrantCallbackGroup
from ..._core._qos import DurabilityPolicy, HistoryPolicy, QoSProfile

__all__ = ["DEFAULT_STATIC_TF_TOPIC", "DEFAULT_TF_TOPIC", "TransformListener"]

DEFAULT_TF_TOPIC = "/tf"
DEFAULT_STATIC_TF_TOPIC = "/tf_static"


class TransformListener:
    """Subscribes ``tf_topic`` and ``tf_static_topic`` on ``node`` and inserts every transform into ``buffer``.

    The subscriptions' callbacks run on the event loop itself (not through the executor), so
    the buffer fills whenever the loop runs: while the program spins, and while a blocking
    ``buffer.lookup_transform(..., timeout)`` waits, from whichever thread or callback.
    ``spin_thread=True`` therefore starts no thread.

    rclpy difference: ``spin_thread=True`` starts no thread and executor of its own: one event
    loop serves every node of the program, run by whichever thread spins or waits. A program
    that never spins still fills the buffer during each lookup with a ``timeout``; a lookup
    without one, between spins, sees only what arrived during earlier spins or waits.
    """

    def __init__(
        self,
        buffer: Any,
        node: Any,
        *,
        spin_thread: bool = False,
        qos: QoSProfile | int | None = None,
        static_qos: QoSProfile | int | None = None,
        tf_topic: str = DEFAULT_TF_TOPIC,
        tf_static_topic: str = DEFAULT_STATIC_TF_TOPIC,
    ) -> None:
        from aiorobot.msgs.tf2_msgs import TFMessage

        from .._node import raw

        if not callable(getattr(buffer, "set_transform", None)):
            raise TypeError(f"TransformListener: expected a tf2_ros.Buffer, got {type(buffer).__name__}: {buffer!r}")
        if qos is None:
            qos = QoSProfile(depth=100, durability=DurabilityPolicy.VOLATILE, history=HistoryPolicy.KEEP_LAST)
        if static_qos is None:
            static_qos = QoSProfile(
                depth=100, durability=DurabilityPolicy.TRANSIENT_LOCAL, history=HistoryPolicy.KEEP_LAST
            )
        self.buffer = buffer
        self.node = node
        self.spin_thread = spin_thread
        self.group = ReentrantCallbackGroup()
        with raw(node):
            self.tf_sub = node.create_subscription(TFMessage, tf_topic, self.callback, qos, callback_group=self.group)
            self.tf_static_sub = node.create_subscription(
                TFMessage, tf_static_topic, self.static_callback, static_qos, callback_group=self.group
            )

    def __repr__(self) -> str:
        return f"<tf2_ros.TransformListener {self.tf_sub.topic_name} {self.tf_static_sub.topic_name} {self.buffer!r}>"

    def unregister(self) -> None:
        """Destroy the two subscriptions."""
        self.node.destroy_subscription(self.tf_sub)
        self.node.destroy_subscription(self.tf_static_sub)

    def callback(self, data: Any) -> None:
        for transform in data.transforms:
            self.buffer.set_transform(transform, "default_authority")

    def static_callback(self, data: Any) -> None:
        set_static = getattr(self.buffer, "set_transform_static", None)
        for transform in data.transforms:
            if set_static is not None:
                set_static(transform, "default_authority")
            else:  # an aiorobot.tf buffer
                self.buffer.set_transform(transform, "default_authority", static=True)
