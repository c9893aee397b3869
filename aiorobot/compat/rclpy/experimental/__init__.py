"""``rclpy.experimental``: rclpy's asyncio node (``AsyncNode``, rclpy 10/11) on aiorobot.

``AsyncPublisher``, ``AsyncSubscription``, ``AsyncService`` and ``AsyncTimer`` are the
entity types an AsyncNode makes (aiorobot's); ``EventsExecutor`` is not provided.
"""

from __future__ import annotations

from ...._core._pubsub import Publisher as AsyncPublisher
from ...._core._pubsub import Subscription as AsyncSubscription
from ...._core._services import Service as AsyncService
from ...._core._timer import Timer as AsyncTimer
from ..._missing import module_getattr
from .async_node import AsyncClient, AsyncClock, AsyncNode

__all__ = [
    "AsyncClient", "AsyncClock", "AsyncNode", "AsyncPublisher", "AsyncService", "AsyncSubscription", "AsyncTimer",
]

__getattr__ = module_getattr(__name__, "rclpy.experimental", {"EventsExecutor"})
