"""``rclpy.lifecycle`` on aiorobot: managed nodes with rclpy's synchronous API (see docs/rclpy-compat.md).

``Node``, ``NodeMixin``, ``State`` and ``Publisher`` are rclpy's aliases of
``LifecycleNode``, ``LifecycleNodeMixin``, ``LifecycleState`` and ``LifecyclePublisher``.
"""

from __future__ import annotations

from .managed_entity import ManagedEntity, SimpleManagedEntity
from .node import LifecycleNode, LifecycleNodeMixin, LifecycleState, TransitionCallbackReturn
from .publisher import LifecyclePublisher

__all__ = [
    "LifecycleNode",
    "LifecycleNodeMixin",
    "LifecyclePublisher",
    "LifecycleState",
    "ManagedEntity",
    "SimpleManagedEntity",
]

# rclpy's aliases, kept out of __all__ as rclpy does (not to be mixed up with rclpy.node.Node)
Node = LifecycleNode
NodeMixin = LifecycleNodeMixin
State = LifecycleState
Publisher = LifecyclePublisher
