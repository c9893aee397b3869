"""``rclpy.event_handler``: QoS event callbacks, over aiorobot._core._event_handler.

The callbacks given here are the program's: the compat node runs them as it runs the
program's other callbacks (in the spinning thread, under the entity's callback group),
and an incompatible-QoS status's ``last_policy_kind`` prints as rclpy's does
(``rmw_qos_policy_kind_t.RMW_QOS_POLICY_DURABILITY``) while staying an int that
``qos_policy_name_from_kind`` takes.

rclpy difference: no default incompatible-QoS/type callbacks: the runtime logs one
warning naming both endpoints of a pair that does not connect (docs/rclpy-differences.md).
"""

from __future__ import annotations

import enum
from collections.abc import Callable
from typing import Any

from ..._core import _event_handler as _eh
from ..._core._event_handler import (
    EventHandler,
    IncompatibleTypeInfo,
    QoSLivelinessChangedInfo,
    QoSLivelinessLostInfo,
    QoSMessageLostInfo,
    QoSOfferedDeadlineMissedInfo,
    QoSOfferedIncompatibleQoSInfo,
    QoSPublisherEventType,
    QoSPublisherMatchedInfo,
    QoSRequestedDeadlineMissedInfo,
    QoSRequestedIncompatibleQoSInfo,
    QoSSubscriptionEventType,
    QoSSubscriptionMatchedInfo,
)

__all__ = [
    "EventHandler", "IncompatibleTypeInfo", "PublisherEventCallbacks", "QoSEventHandler",
    "QoSLivelinessChangedInfo", "QoSLivelinessLostInfo", "QoSMessageLostInfo", "QoSOfferedDeadlineMissedInfo",
    "QoSOfferedIncompatibleQoSInfo", "QoSPublisherEventType", "QoSPublisherMatchedInfo",
    "QoSRequestedDeadlineMissedInfo", "QoSRequestedIncompatibleQoSInfo", "QoSSubscriptionEventType",
    "QoSSubscriptionMatchedInfo", "SubscriptionEventCallbacks",
    "UnsupportedEventTypeError",
]


class UnsupportedEventTypeError(Exception):
    """An event type the middleware does not support (aiorobot supports all it lists; never raised)."""


class rmw_qos_policy_kind_t(enum.IntEnum):  # noqa: N801  (rclpy's pybind11 enum name)
    """The type of ``last_policy_kind`` in rclpy (values as ``QoSPolicyKind``'s)."""

    RMW_QOS_POLICY_INVALID = 1 << 0
    RMW_QOS_POLICY_DURABILITY = 1 << 1
    RMW_QOS_POLICY_DEADLINE = 1 << 2
    RMW_QOS_POLICY_LIVELINESS = 1 << 3
    RMW_QOS_POLICY_RELIABILITY = 1 << 4
    RMW_QOS_POLICY_HISTORY = 1 << 5
    RMW_QOS_POLICY_LIFESPAN = 1 << 6
    RMW_QOS_POLICY_DEPTH = 1 << 7
    RMW_QOS_POLICY_LIVELINESS_LEASE_DURATION = 1 << 8
    RMW_QOS_POLICY_AVOID_ROS_NAMESPACE_CONVENTIONS = 1 << 9

    def __str__(self) -> str:  # pybind11's enum str
        return f"rmw_qos_policy_kind_t.{self.name}"

    def __format__(self, spec: str) -> str:  # f-strings print the name too
        return format(str(self), spec)


def rclpy_status(status: Any) -> Any:
    """``status`` as rclpy's callback gets it (``last_policy_kind`` as rclpy's enum)."""
    if isinstance(status, QoSRequestedIncompatibleQoSInfo):
        import dataclasses

        return dataclasses.replace(status, last_policy_kind=rmw_qos_policy_kind_t(int(status.last_policy_kind)))
    return status


class SubscriptionEventCallbacks(_eh.SubscriptionEventCallbacks):
    """rclpy's ``SubscriptionEventCallbacks``."""

    def __init__(
        self, *, deadline: Callable[..., Any] | None = None, incompatible_qos: Callable[..., Any] | None = None,
        liveliness: Callable[..., Any] | None = None, message_lost: Callable[..., Any] | None = None,
        incompatible_type: Callable[..., Any] | None = None, matched: Callable[..., Any] | None = None,
        use_default_callbacks: bool = True,
    ) -> None:
        super().__init__(
            deadline=deadline, incompatible_qos=incompatible_qos, liveliness=liveliness, message_lost=message_lost,
            incompatible_type=incompatible_type, matched=matched, use_default_callbacks=use_default_callbacks,
        )


class PublisherEventCallbacks(_eh.PublisherEventCallbacks):
    """rclpy's ``PublisherEventCallbacks``."""

    def __init__(
        self, *, deadline: Callable[..., Any] | None = None, liveliness: Callable[..., Any] | None = None,
        incompatible_qos: Callable[..., Any] | None = None, incompatible_type: Callable[..., Any] | None = None,
        matched: Callable[..., Any] | None = None, use_default_callbacks: bool = True,
    ) -> None:
        super().__init__(
            deadline=deadline, liveliness=liveliness, incompatible_qos=incompatible_qos,
            incompatible_type=incompatible_type, matched=matched, use_default_callbacks=use_default_callbacks,
        )


#: rclpy's deprecated name.
QoSEventHandler = EventHandler

