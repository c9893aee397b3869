"""aiorobot: an async-first asyncio robotics framework.

Nodes, topics, QoS, timers, callback groups, parameters and ROS 2 messages,
asyncio-native, with a priority loop for control. See API.md for the contract.
"""

from __future__ import annotations

from ._actions import (
    ActionClient,
    ActionServer,
    CancelResponse,
    ClientGoalHandle,
    GoalResponse,
    GoalStatus,
    ServerGoalHandle,
)
from ._clock import Clock
from ._config import ConfigError, GraphConfig, load_config
from ._errors import (
    InvalidNameError,
    InvalidParameterValueError,
    ParameterAlreadyDeclaredError,
    ParameterError,
    ParameterNotDeclaredError,
    QoSIncompatibleError,
    ServiceError,
)
from ._graph import EndpointInfo, Graph, NodeInfo, ServiceInfo, TopicInfo
from ._groups import CallbackGroup, MutuallyExclusiveCallbackGroup, ReentrantCallbackGroup
from ._logging import NodeLogger, setup_logging
from ._node import Node
from ._parameters import (
    Parameter,
    ParameterDescriptor,
    ParameterType,
    SetParametersResult,
)
from ._pubsub import MessageStream, Publisher, Subscription
from ._qos import (
    DurabilityPolicy,
    HistoryPolicy,
    QoSProfile,
    ReliabilityPolicy,
    qos_profile_sensor_data,
    qos_profile_system_default,
)
from ._runtime import Runtime, run
from ._services import Client, Service, ServiceUnavailableError
from ._time import ClockType, Duration, Time
from ._timer import Rate, Timer, TimerStatistics
from ._transport import LocalTransport, Transport

__version__ = "0.1.0"

__all__ = [
    "ActionClient",
    "ActionServer",
    "CancelResponse",
    "ClientGoalHandle",
    "GoalResponse",
    "GoalStatus",
    "ServerGoalHandle",
    "CallbackGroup",
    "Client",
    "ConfigError",
    "Clock",
    "ClockType",
    "DurabilityPolicy",
    "Duration",
    "EndpointInfo",
    "Graph",
    "GraphConfig",
    "HistoryPolicy",
    "InvalidNameError",
    "InvalidParameterValueError",
    "LocalTransport",
    "MessageStream",
    "MutuallyExclusiveCallbackGroup",
    "Node",
    "NodeInfo",
    "NodeLogger",
    "Parameter",
    "ParameterAlreadyDeclaredError",
    "ParameterDescriptor",
    "ParameterError",
    "ParameterNotDeclaredError",
    "ParameterType",
    "Publisher",
    "QoSIncompatibleError",
    "QoSProfile",
    "Rate",
    "ReentrantCallbackGroup",
    "ReliabilityPolicy",
    "Runtime",
    "Service",
    "ServiceError",
    "ServiceInfo",
    "ServiceUnavailableError",
    "SetParametersResult",
    "Subscription",
    "Time",
    "Timer",
    "TimerStatistics",
    "TopicInfo",
    "Transport",
    "load_config",
    "qos_profile_sensor_data",
    "qos_profile_system_default",
    "run",
    "setup_logging",
]
