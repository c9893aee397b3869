"""``rclpy.qos``: aiorobot's profiles and policies under rclpy's names (and their QoS* aliases).

``QoSProfile`` here is rclpy's: its policies can be set after construction
(``profile.durability = QoSDurabilityPolicy.TRANSIENT_LOCAL``), each value checked and
coerced as the constructor does. The compat node copies it into aiorobot's frozen profile
when it makes the entity, so a later change does not reach the entity, as in rclpy.
"""

from __future__ import annotations

import dataclasses
from typing import Any

from ..._core import _qos
from ..._core._qos import (
    DurabilityPolicy,
    HistoryPolicy,
    LivelinessPolicy,
    QoSPolicyKind,
    QoSPresetProfiles,
    ReliabilityPolicy,
    qos_policy_name_from_kind,
    qos_profile_sensor_data,
    qos_profile_system_default,
)
from ..._core._logging import ROSOUT_QOS
from .._missing import module_getattr

__all__ = [
    "DurabilityPolicy", "HistoryPolicy", "LivelinessPolicy", "QoSDurabilityPolicy", "QoSHistoryPolicy",
    "QoSLivelinessPolicy", "QoSPolicyKind", "QoSPresetProfiles", "QoSProfile", "QoSReliabilityPolicy",
    "ReliabilityPolicy", "qos_policy_name_from_kind", "qos_profile_parameter_events", "qos_profile_parameters",
    "qos_profile_rosout_default", "qos_profile_sensor_data", "qos_profile_services_default", "qos_profile_system_default",
]

_FIELDS = tuple(f.name for f in dataclasses.fields(_qos.QoSProfile))


class QoSProfile(_qos.QoSProfile):
    """rclpy's mutable ``QoSProfile`` over aiorobot's (equal to an aiorobot profile of the same policies)."""

    __slots__ = ()

    def __setattr__(self, name: str, value: Any) -> None:
        if name not in _FIELDS:
            raise AttributeError(f"'QoSProfile' object has no attribute {name!r}")
        # the constructor's checks and coercions (policy ints to enums, Duration or None)
        checked = _qos.QoSProfile(**{**{f: getattr(self, f) for f in _FIELDS}, name: value})
        object.__setattr__(self, name, getattr(checked, name))

    def __delattr__(self, name: str) -> None:
        raise AttributeError(f"QoSProfile.{name} cannot be deleted")

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, _qos.QoSProfile):
            return NotImplemented
        return all(getattr(self, f) == getattr(other, f) for f in _FIELDS)

    __hash__ = None  # type: ignore[assignment]  # mutable, as rclpy's


def frozen(profile: Any) -> Any:
    """aiorobot's frozen copy of a (mutable) compat profile; anything else unchanged."""
    if isinstance(profile, QoSProfile):
        return _qos.QoSProfile(**{f: getattr(profile, f) for f in _FIELDS})
    return profile


QoSDurabilityPolicy = DurabilityPolicy
QoSHistoryPolicy = HistoryPolicy
QoSLivelinessPolicy = LivelinessPolicy
QoSReliabilityPolicy = ReliabilityPolicy
qos_profile_services_default = _qos.QoSProfile()
qos_profile_parameters = _qos.QoSProfile(depth=1000)
qos_profile_parameter_events = _qos.QoSProfile(depth=1000)
qos_profile_rosout_default = ROSOUT_QOS  # what every node's /rosout publisher uses

__getattr__ = module_getattr(
    __name__, "rclpy.qos",
    {"qos_profile_unknown", "qos_profile_action_status_default", "qos_check_compatible", "QoSCompatibility",
     "InvalidQoSProfileException"},
)
