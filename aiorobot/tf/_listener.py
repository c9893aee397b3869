"""Filling a :class:`Buffer` from ``/tf`` and ``/tf_static``, as tf2_ros's TransformListener."""

from __future__ import annotations

from typing import Any

from aiorobot._core._qos import QoSProfile

from ._broadcasters import DYNAMIC_QOS, STATIC_QOS
from ._buffer_core import BufferCore
from ._exceptions import TransformException

__all__ = ["TransformListener"]


class TransformListener:
    """Subscribes ``/tf`` (reliable, volatile, depth 100) and ``/tf_static``
    (reliable, transient local, depth 1) on ``node`` and inserts every transform
    into ``buffer``.

    Samples from the network that the buffer refuses (NaN, a bad quaternion,
    empty or self-referencing frame ids) are logged, throttled, and dropped; the
    rest of their ``TFMessage`` is still used.

    The buffer is thread safe: the listener's node may run on one loop while
    other nodes (the priority loop's controllers) look transforms up.
    """

    def __init__(
        self,
        buffer: BufferCore,
        node: Any,
        *,
        tf_topic: str = "/tf",
        tf_static_topic: str = "/tf_static",
        qos: QoSProfile = DYNAMIC_QOS,
        static_qos: QoSProfile = STATIC_QOS,
    ) -> None:
        from aiorobot.msgs.tf2_msgs import TFMessage

        if not isinstance(buffer, BufferCore):
            raise TypeError(f"expected an aiorobot.tf.Buffer, got {type(buffer).__name__}: {buffer!r}")
        self.buffer = buffer
        self._node = node
        self._logger = node.get_logger()
        self.received = 0
        self.dropped = 0
        self._subs = (
            node.create_subscription(TFMessage, tf_topic, self._on_tf, qos),
            node.create_subscription(TFMessage, tf_static_topic, self._on_tf_static, static_qos),
        )

    def __repr__(self) -> str:
        return f"<TransformListener received={self.received} dropped={self.dropped} {self.buffer!r}>"

    def _on_tf(self, msg: Any) -> None:
        self._insert(msg, static=False)

    def _on_tf_static(self, msg: Any) -> None:
        self._insert(msg, static=True)

    def _insert(self, msg: Any, *, static: bool) -> None:
        for transform in msg.transforms:
            self.received += 1
            try:
                self.buffer.set_transform(transform, "default_authority", static=static)
            except TransformException as exc:
                self.dropped += 1
                self._logger.warning(
                    f"dropped a transform received on {'/tf_static' if static else '/tf'}: {exc}",
                    throttle_duration_sec=5.0,
                )
