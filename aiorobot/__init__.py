"""aiorobot: an async-first asyncio robotics framework.

Nodes, topics, QoS, timers, callback groups, parameters, services, actions and
ROS 2 messages, asyncio-native, with a priority loop for control. The public
API is listed in docs/api.md in the repository; help(aiorobot.Node) and friends
show each name's documentation.

Public names are imported on first use (PEP 562), so ``import aiorobot.msgs``
or ``aiorobot --help`` pay only for what they touch.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

__version__ = "0.1.0"

#: The public names, each with the module that defines it: the one list. ``__all__`` is derived
#: from it, and tests/core/test_public_api.py checks that the TYPE_CHECKING imports below agree.
_EXPORTS = {
    "ConfigError": "launch",
    "GraphConfig": "launch",
    "load_config": "launch",
    "ActionClient": "_core._actions",
    "ActionServer": "_core._actions",
    "CancelResponse": "_core._actions",
    "ClientGoalHandle": "_core._actions",
    "GoalResponse": "_core._actions",
    "GoalStatus": "_core._actions",
    "ServerGoalHandle": "_core._actions",
    "Clock": "_core._clock",
    "ClockChange": "_core._clock",
    "JumpHandle": "_core._clock",
    "JumpThreshold": "_core._clock",
    "ROSClock": "_core._clock",
    "TimeJump": "_core._clock",
    "ClockPublisher": "_core._clock_publisher",
    "InvalidNameError": "_core._errors",
    "InvalidParameterTypeError": "_core._errors",
    "InvalidParameterValueError": "_core._errors",
    "ParameterAlreadyDeclaredError": "_core._errors",
    "ParameterError": "_core._errors",
    "ParameterImmutableError": "_core._errors",
    "ParameterNotDeclaredError": "_core._errors",
    "ParameterUninitializedError": "_core._errors",
    "QoSIncompatibleError": "_core._errors",
    "ServiceError": "_core._errors",
    "EventHandler": "_core._event_handler",
    "IncompatibleTypeInfo": "_core._event_handler",
    "PublisherEventCallbacks": "_core._event_handler",
    "QoSLivelinessChangedInfo": "_core._event_handler",
    "QoSLivelinessLostInfo": "_core._event_handler",
    "QoSMessageLostInfo": "_core._event_handler",
    "QoSOfferedDeadlineMissedInfo": "_core._event_handler",
    "QoSOfferedIncompatibleQoSInfo": "_core._event_handler",
    "QoSPublisherEventType": "_core._event_handler",
    "QoSPublisherMatchedInfo": "_core._event_handler",
    "QoSRequestedDeadlineMissedInfo": "_core._event_handler",
    "QoSRequestedIncompatibleQoSInfo": "_core._event_handler",
    "QoSSubscriptionEventType": "_core._event_handler",
    "QoSSubscriptionMatchedInfo": "_core._event_handler",
    "SubscriptionEventCallbacks": "_core._event_handler",
    "Future": "_core._future",
    "EndpointInfo": "_core._graph",
    "Graph": "_core._graph",
    "NodeInfo": "_core._graph",
    "ServiceInfo": "_core._graph",
    "TopicInfo": "_core._graph",
    "CallbackGroup": "_core._groups",
    "MutuallyExclusiveCallbackGroup": "_core._groups",
    "ReentrantCallbackGroup": "_core._groups",
    "NodeLogger": "_core._logging",
    "setup_logging": "_core._logging",
    "Node": "_core._node",
    "NodeNameNonExistentError": "_core._node_graph",
    "FloatingPointRange": "_core._parameter_types",
    "IntegerRange": "_core._parameter_types",
    "Parameter": "_core._parameter_types",
    "ParameterDescriptor": "_core._parameter_types",
    "ParameterType": "_core._parameter_types",
    "SetParametersResult": "_core._parameter_types",
    "MessageInfo": "_core._pubsub",
    "MessageStream": "_core._pubsub",
    "Publisher": "_core._pubsub",
    "Subscription": "_core._pubsub",
    "DurabilityPolicy": "_core._qos",
    "HistoryPolicy": "_core._qos",
    "LivelinessPolicy": "_core._qos",
    "qos_policy_name_from_kind": "_core._qos",
    "qos_profile_sensor_data": "_core._qos",
    "qos_profile_system_default": "_core._qos",
    "QoSPolicyKind": "_core._qos",
    "QoSPresetProfiles": "_core._qos",
    "QoSProfile": "_core._qos",
    "ReliabilityPolicy": "_core._qos",
    "run": "_core._runtime",
    "Runtime": "_core._runtime",
    "Client": "_core._services",
    "Service": "_core._services",
    "ServiceUnavailableError": "_core._services",
    "ClockType": "_core._time",
    "Duration": "_core._time",
    "Infinite": "_core._time",
    "Time": "_core._time",
    "Rate": "_core._timer",
    "Timer": "_core._timer",
    "TimerInfo": "_core._timer",
    "TimerStatistics": "_core._timer",
    "LocalTransport": "_core._transport",
    "Transport": "_core._transport",
    "compile_kernels": "_core._warm_up",
}

__all__ = sorted(_EXPORTS, key=str.lower)

if TYPE_CHECKING:
    from ._core._actions import ActionClient, ActionServer, CancelResponse, ClientGoalHandle, GoalResponse, GoalStatus, ServerGoalHandle
    from ._core._clock import Clock, ClockChange, JumpHandle, JumpThreshold, ROSClock, TimeJump
    from ._core._clock_publisher import ClockPublisher
    from .launch import ConfigError, GraphConfig, load_config
    from ._core._errors import InvalidParameterTypeError, ParameterImmutableError, ParameterUninitializedError
    from ._core._errors import InvalidNameError, InvalidParameterValueError, ParameterAlreadyDeclaredError, ParameterError, ParameterNotDeclaredError, QoSIncompatibleError, ServiceError
    from ._core._future import Future
    from ._core._graph import EndpointInfo, Graph, NodeInfo, ServiceInfo, TopicInfo
    from ._core._node_graph import NodeNameNonExistentError
    from ._core._groups import CallbackGroup, MutuallyExclusiveCallbackGroup, ReentrantCallbackGroup
    from ._core._logging import NodeLogger, setup_logging
    from ._core._node import Node
    from ._core._parameter_types import FloatingPointRange, IntegerRange, Parameter, ParameterDescriptor, ParameterType, SetParametersResult
    from ._core._event_handler import EventHandler, IncompatibleTypeInfo, PublisherEventCallbacks, QoSLivelinessChangedInfo, QoSLivelinessLostInfo, QoSMessageLostInfo, QoSOfferedDeadlineMissedInfo, QoSOfferedIncompatibleQoSInfo, QoSPublisherEventType, QoSPublisherMatchedInfo, QoSRequestedDeadlineMissedInfo, QoSRequestedIncompatibleQoSInfo, QoSSubscriptionEventType, QoSSubscriptionMatchedInfo, SubscriptionEventCallbacks
    from ._core._pubsub import MessageInfo, MessageStream, Publisher, Subscription
    from ._core._qos import LivelinessPolicy, QoSPolicyKind, qos_policy_name_from_kind
    from ._core._qos import DurabilityPolicy, HistoryPolicy, QoSPresetProfiles, QoSProfile, ReliabilityPolicy, qos_profile_sensor_data, qos_profile_system_default
    from ._core._runtime import Runtime, run
    from ._core._services import Client, Service, ServiceUnavailableError
    from ._core._time import ClockType, Duration, Infinite, Time
    from ._core._timer import Rate, Timer, TimerInfo, TimerStatistics
    from ._core._transport import LocalTransport, Transport
    from ._core._warm_up import compile_kernels


_SUBPACKAGES = frozenset(
    {"control", "fusion", "lifecycle", "message_filters", "msgs", "parameters", "perception", "testing", "tf"}
)


#: Packages loaded with a public name because they plug into it (the core never imports them):
#: aiorobot.launch installs the loader behind ``Runtime(config=...)``.
_PLUGINS = {"Runtime": ("aiorobot.launch",)}


def __getattr__(name: str) -> Any:
    if name in _SUBPACKAGES:
        return importlib.import_module(f"aiorobot.{name}")
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'aiorobot' has no attribute {name!r}")
    value = getattr(importlib.import_module(f"aiorobot.{module}"), name)
    for plugin in _PLUGINS.get(name, ()):
        importlib.import_module(plugin)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
