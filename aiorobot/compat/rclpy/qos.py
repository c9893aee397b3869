"""``rclpy.qos``: aiorobot's profiles and policies under rclpy's names (and their QoS* aliases)."""

from __future__ import annotations

from ..._qos import (
    DurabilityPolicy,
    HistoryPolicy,
    QoSPresetProfiles,
    QoSProfile,
    ReliabilityPolicy,
    qos_profile_sensor_data,
    qos_profile_system_default,
)
from .._missing import module_getattr

__all__ = [
    "DurabilityPolicy", "HistoryPolicy", "QoSDurabilityPolicy", "QoSHistoryPolicy", "QoSPresetProfiles",
    "QoSProfile", "QoSReliabilityPolicy", "ReliabilityPolicy", "qos_profile_parameter_events",
    "qos_profile_parameters", "qos_profile_sensor_data", "qos_profile_services_default",
    "qos_profile_system_default",
]

QoSDurabilityPolicy = DurabilityPolicy
QoSHistoryPolicy = HistoryPolicy
QoSReliabilityPolicy = ReliabilityPolicy
qos_profile_services_default = QoSProfile()
qos_profile_parameters = QoSProfile(depth=1000)
qos_profile_parameter_events = QoSProfile(depth=1000)

__getattr__ = module_getattr(
    __name__, "rclpy.qos",
    {"LivelinessPolicy", "QoSLivelinessPolicy", "qos_profile_unknown", "qos_profile_action_status_default",
     "qos_check_compatible", "QoSCompatibility", "InvalidQoSProfileException"},
)
