"""``rclpy.node``: ``Node`` with rclpy's constructor, on aiorobot's ``Node``."""

from __future__ import annotations

from typing import Any

from ..._core._node import Node as _AioNode
from .._missing import module_getattr
from .._node import make_node_class

__all__ = ["Node"]

Node: Any = make_node_class(
    _AioNode,
    "Node",
    __name__,
    "rclpy's Node on aiorobot: joins the context's runtime at construction; callbacks run when "
    "an executor spins (see docs/rclpy-compat.md).",
)

__getattr__ = module_getattr(__name__, "rclpy.node", {"HIDDEN_NODE_PREFIX", "NodeNameNonExistentError"})
