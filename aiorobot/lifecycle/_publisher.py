"""A publisher that delivers only while its lifecycle node is active."""

from __future__ import annotations

from typing import TYPE_CHECKING, Generic, TypeVar

if TYPE_CHECKING:
    from .._core._pubsub import Publisher
    from ._node import LifecycleNode

__all__ = ["LifecyclePublisher"]

M = TypeVar("M")


class LifecyclePublisher(Generic[M]):
    """Created by ``LifecycleNode.create_lifecycle_publisher``; ``publish`` is a no-op unless activated.

    The node activates its lifecycle publishers when it becomes ``active`` and
    deactivates them when it leaves ``active`` (so they stay silent in
    ``on_deactivate``); a hook may call :meth:`on_activate` itself to publish
    earlier, e.g. from ``on_activate``, and that lasts until the next state change.
    Publishing while deactivated logs a warning once, and again only after the
    publisher has been activated in between (as rclcpp's ``LifecyclePublisher``).
    """

    def __init__(self, node: LifecycleNode, publisher: Publisher[M]) -> None:
        self._node = node
        self.publisher = publisher
        self._activated = False
        self._should_log = True
        self.suppressed = 0

    def __repr__(self) -> str:
        state = "activated" if self._activated else "deactivated"
        return f"<LifecyclePublisher {self.topic_name} {self.publisher.type_name} {state}>"

    @property
    def topic_name(self) -> str:
        return self.publisher.topic_name

    @property
    def msg_type(self) -> type[M]:
        return self.publisher.msg_type

    @property
    def is_activated(self) -> bool:
        return self._activated

    def get_subscription_count(self) -> int:
        return self.publisher.get_subscription_count()

    def on_activate(self) -> None:
        self._activated = True
        self._should_log = True

    def on_deactivate(self) -> None:
        self._activated = False

    def publish(self, msg: M) -> None:
        """Publish ``msg`` if activated; otherwise drop it (warning once per deactivated period)."""
        if not self._activated:
            self.suppressed += 1
            if self._should_log:
                self._should_log = False
                self._node.get_logger().warning(
                    f"Trying to publish message on the topic '{self.topic_name}', but the publisher is not "
                    f"activated (node state {self._node.current_state.label!r}); activate the node first"
                )
            return
        self.publisher.publish(msg)

    def destroy(self) -> None:
        self._node._destroy_lifecycle_publisher(self)
