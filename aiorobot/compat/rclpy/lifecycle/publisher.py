"""``rclpy.lifecycle.publisher``: a publisher that delivers only while activated."""

from __future__ import annotations

from typing import Any, Generic, TypeVar

from ...._core._pubsub import Publisher
from .managed_entity import SimpleManagedEntity

__all__ = ["LifecyclePublisher"]

MsgT = TypeVar("MsgT")


class LifecyclePublisher(SimpleManagedEntity, Generic[MsgT]):
    """Managed publisher entity (``LifecycleNode.create_lifecycle_publisher``).

    As rclpy's: the node's default ``on_activate`` / ``on_deactivate`` switch it on and
    off (a node overriding them must call ``super()``), and ``publish`` while not
    activated drops the message without a word. Every other attribute is the wrapped
    aiorobot :class:`~aiorobot.Publisher`'s (``topic_name``, ``get_subscription_count``, ...).

    Differs from rclpy (see docs/rclpy-compat.md): it wraps the publisher instead of subclassing
    ``rclpy.publisher.Publisher``.
    """

    def __init__(self, publisher: Publisher[MsgT]) -> None:
        SimpleManagedEntity.__init__(self)
        self.publisher = publisher

    def __repr__(self) -> str:
        state = "activated" if self._enabled else "deactivated"
        return f"<LifecyclePublisher {self.publisher.topic_name} {self.publisher.type_name} {state}>"

    def __getattr__(self, name: str) -> Any:
        if name == "publisher":
            raise AttributeError(name)
        return getattr(self.publisher, name)

    @SimpleManagedEntity.when_enabled
    def publish(self, msg: MsgT) -> None:
        """Publish ``msg`` if the lifecycle publisher is activated (see rclpy's ``Publisher.publish``)."""
        self.publisher.publish(msg)

    def destroy(self) -> None:
        self.publisher.node.destroy_publisher(self)
