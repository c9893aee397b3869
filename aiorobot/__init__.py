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

_EXPORTS = {
    "ParameterUninitializedError": "_errors",
    "ParameterImmutableError": "_errors",
    "InvalidParameterTypeError": "_errors",
    "IntegerRange": "_parameters",
    "FloatingPointRange": "_parameters",
    "ActionClient": "_actions",
    "ActionServer": "_actions",
    "CallbackGroup": "_groups",
    "CancelResponse": "_actions",
    "Client": "_services",
    "ClientGoalHandle": "_actions",
    "Clock": "_clock",
    "ClockPublisher": "_clock_publisher",
    "ClockType": "_time",
    "ClockChange": "_clock",
    "Infinite": "_time",
    "JumpHandle": "_clock",
    "JumpThreshold": "_clock",
    "ROSClock": "_clock",
    "TimeJump": "_clock",
    "ConfigError": "launch",
    "DurabilityPolicy": "_qos",
    "EventHandler": "_event_handler",
    "IncompatibleTypeInfo": "_event_handler",
    "PublisherEventCallbacks": "_event_handler",
    "QoSLivelinessChangedInfo": "_event_handler",
    "QoSLivelinessLostInfo": "_event_handler",
    "QoSMessageLostInfo": "_event_handler",
    "QoSOfferedDeadlineMissedInfo": "_event_handler",
    "QoSOfferedIncompatibleQoSInfo": "_event_handler",
    "QoSPublisherEventType": "_event_handler",
    "QoSPublisherMatchedInfo": "_event_handler",
    "QoSRequestedDeadlineMissedInfo": "_event_handler",
    "QoSRequestedIncompatibleQoSInfo": "_event_handler",
    "QoSSubscriptionEventType": "_event_handler",
    "QoSSubscriptionMatchedInfo": "_event_handler",
    "SubscriptionEventCallbacks": "_event_handler",
    "LivelinessPolicy": "_qos",
    "QoSPolicyKind": "_qos",
    "qos_policy_name_from_kind": "_qos",
    "MessageInfo": "_pubsub",
    "Duration": "_time",
    "EndpointInfo": "_graph",
    "Future": "_future",
    "GoalResponse": "_actions",
    "GoalStatus": "_actions",
    "Graph": "_graph",
    "GraphConfig": "launch",
    "HistoryPolicy": "_qos",
    "InvalidNameError": "_errors",
    "InvalidParameterValueError": "_errors",
    "LocalTransport": "_transport",
    "MessageStream": "_pubsub",
    "MutuallyExclusiveCallbackGroup": "_groups",
    "Node": "_node",
    "NodeInfo": "_graph",
    "NodeNameNonExistentError": "_node_graph",
    "NodeLogger": "_logging",
    "Parameter": "_parameters",
    "ParameterAlreadyDeclaredError": "_errors",
    "ParameterDescriptor": "_parameters",
    "ParameterError": "_errors",
    "ParameterNotDeclaredError": "_errors",
    "ParameterType": "_parameters",
    "Publisher": "_pubsub",
    "QoSIncompatibleError": "_errors",
    "QoSPresetProfiles": "_qos",
    "QoSProfile": "_qos",
    "Rate": "_timer",
    "ReentrantCallbackGroup": "_groups",
    "ReliabilityPolicy": "_qos",
    "Runtime": "_runtime",
    "ServerGoalHandle": "_actions",
    "Service": "_services",
    "ServiceError": "_errors",
    "ServiceInfo": "_graph",
    "ServiceUnavailableError": "_services",
    "SetParametersResult": "_parameters",
    "Subscription": "_pubsub",
    "Time": "_time",
    "Timer": "_timer",
    "TimerInfo": "_timer",
    "TimerStatistics": "_timer",
    "TopicInfo": "_graph",
    "Transport": "_transport",
    "compile_kernels": "_warm_up",
    "load_config": "launch",
    "qos_profile_sensor_data": "_qos",
    "qos_profile_system_default": "_qos",
    "run": "_runtime",
    "setup_logging": "_logging",
}

__all__ = [
    "ActionClient",
    "ActionServer",
    "CallbackGroup",
    "CancelResponse",
    "Client",
    "ClientGoalHandle",
    "Clock",
    "ClockChange",
    "ClockPublisher",
    "ClockType",
    "compile_kernels",
    "ConfigError",
    "DurabilityPolicy",
    "Duration",
    "EndpointInfo",
    "EventHandler",
    "FloatingPointRange",
    "Future",
    "GoalResponse",
    "GoalStatus",
    "Graph",
    "GraphConfig",
    "HistoryPolicy",
    "IncompatibleTypeInfo",
    "Infinite",
    "IntegerRange",
    "InvalidNameError",
    "InvalidParameterTypeError",
    "InvalidParameterValueError",
    "JumpHandle",
    "JumpThreshold",
    "LivelinessPolicy",
    "load_config",
    "LocalTransport",
    "MessageInfo",
    "MessageStream",
    "MutuallyExclusiveCallbackGroup",
    "Node",
    "NodeInfo",
    "NodeLogger",
    "NodeNameNonExistentError",
    "Parameter",
    "ParameterAlreadyDeclaredError",
    "ParameterDescriptor",
    "ParameterError",
    "ParameterImmutableError",
    "ParameterNotDeclaredError",
    "ParameterType",
    "ParameterUninitializedError",
    "Publisher",
    "PublisherEventCallbacks",
    "qos_policy_name_from_kind",
    "qos_profile_sensor_data",
    "qos_profile_system_default",
    "QoSIncompatibleError",
    "QoSLivelinessChangedInfo",
    "QoSLivelinessLostInfo",
    "QoSMessageLostInfo",
    "QoSOfferedDeadlineMissedInfo",
    "QoSOfferedIncompatibleQoSInfo",
    "QoSPolicyKind",
    "QoSPresetProfiles",
    "QoSProfile",
    "QoSPublisherEventType",
    "QoSPublisherMatchedInfo",
    "QoSRequestedDeadlineMissedInfo",
    "QoSRequestedIncompatibleQoSInfo",
    "QoSSubscriptionEventType",
    "QoSSubscriptionMatchedInfo",
    "Rate",
    "ReentrantCallbackGroup",
    "ReliabilityPolicy",
    "ROSClock",
    "run",
    "Runtime",
    "ServerGoalHandle",
    "Service",
    "ServiceError",
    "ServiceInfo",
    "ServiceUnavailableError",
    "SetParametersResult",
    "setup_logging",
    "Subscription",
    "SubscriptionEventCallbacks",
    "Time",
    "TimeJump",
    "Timer",
    "TimerInfo",
    "TimerStatistics",
    "TopicInfo",
    "Transport",
]

if TYPE_CHECKING:
    from ._actions import ActionClient, ActionServer, CancelResponse, ClientGoalHandle, GoalResponse, GoalStatus, ServerGoalHandle
    from ._clock import Clock, ClockChange, JumpHandle, JumpThreshold, ROSClock, TimeJump
    from ._clock_publisher import ClockPublisher
    from .launch import ConfigError, GraphConfig, load_config
    from ._errors import InvalidParameterTypeError, ParameterImmutableError, ParameterUninitializedError
    from ._errors import InvalidNameError, InvalidParameterValueError, ParameterAlreadyDeclaredError, ParameterError, ParameterNotDeclaredError, QoSIncompatibleError, ServiceError
    from ._future import Future
    from ._graph import EndpointInfo, Graph, NodeInfo, ServiceInfo, TopicInfo
    from ._node_graph import NodeNameNonExistentError
    from ._groups import CallbackGroup, MutuallyExclusiveCallbackGroup, ReentrantCallbackGroup
    from ._logging import NodeLogger, setup_logging
    from ._node import Node
    from ._parameters import FloatingPointRange, IntegerRange, Parameter, ParameterDescriptor, ParameterType, SetParametersResult
    from ._event_handler import EventHandler, IncompatibleTypeInfo, PublisherEventCallbacks, QoSLivelinessChangedInfo, QoSLivelinessLostInfo, QoSMessageLostInfo, QoSOfferedDeadlineMissedInfo, QoSOfferedIncompatibleQoSInfo, QoSPublisherEventType, QoSPublisherMatchedInfo, QoSRequestedDeadlineMissedInfo, QoSRequestedIncompatibleQoSInfo, QoSSubscriptionEventType, QoSSubscriptionMatchedInfo, SubscriptionEventCallbacks
    from ._pubsub import MessageInfo, MessageStream, Publisher, Subscription
    from ._qos import LivelinessPolicy, QoSPolicyKind, qos_policy_name_from_kind
    from ._qos import DurabilityPolicy, HistoryPolicy, QoSPresetProfiles, QoSProfile, ReliabilityPolicy, qos_profile_sensor_data, qos_profile_system_default
    from ._runtime import Runtime, run
    from ._services import Client, Service, ServiceUnavailableError
    from ._time import ClockType, Duration, Infinite, Time
    from ._timer import Rate, Timer, TimerInfo, TimerStatistics
    from ._transport import LocalTransport, Transport
    from ._warm_up import compile_kernels


#: Packages loaded with a public name because they plug into it (the core never imports them):
#: aiorobot.launch installs the loader behind ``Runtime(config=...)``.
_PLUGINS = {"Runtime": ("aiorobot.launch",)}

_SUBPACKAGES = frozenset(
    {"control", "fusion", "lifecycle", "message_filters", "msgs", "parameters", "perception", "testing", "tf"}
)


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
