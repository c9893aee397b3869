"""``rclpy.qos_overriding_options``: QoS profiles configurable through parameters, as rclpy's.

``create_publisher(..., qos_overriding_options=QoSOverridingOptions.with_default_policies())``
declares one read-only parameter per policy kind,
``qos_overrides.<resolved topic>.publisher|subscription[_<entity_id>].<policy>``, whose
default is the profile's value; an override (``-p``, ``--params-file``, ``parameter_overrides``)
replaces it before the entity is made. The options' callback then validates the resulting
profile, and a result that is not ``successful`` raises :class:`InvalidQosOverridesError`
with rclpy's message.

rclpy difference: the ``avoid_ros_namespace_conventions`` policy kind is not provided
(aiorobot's profiles have no such policy).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from typing import Any

from ..._core import _qos
from ...msgs import rcl_interfaces as _ri
from ..._core._errors import ParameterAlreadyDeclaredError
from ..._core._time import Duration
from .._missing import not_provided
from .qos import QoSPolicyKind, QoSProfile, frozen

__all__ = ["InvalidQosOverridesError", "QoSOverridingOptions", "QosCallbackResult", "QosCallbackType"]


class InvalidQosOverridesError(Exception):
    """The options' callback refused the profile the overrides made."""


#: What a validation callback returns (rcl_interfaces' ``SetParametersResult``, as in rclpy).
QosCallbackResult = _ri.SetParametersResult
QosCallbackType = Callable[[Any], Any]

_ENUMS = {
    QoSPolicyKind.HISTORY: _qos.HistoryPolicy,
    QoSPolicyKind.RELIABILITY: _qos.ReliabilityPolicy,
    QoSPolicyKind.DURABILITY: _qos.DurabilityPolicy,
    QoSPolicyKind.LIVELINESS: _qos.LivelinessPolicy,
}
_DURATIONS = (QoSPolicyKind.LIFESPAN, QoSPolicyKind.DEADLINE, QoSPolicyKind.LIVELINESS_LEASE_DURATION)


class QoSOverridingOptions:
    """Which policies of an entity get a parameter, the validation callback, and the entity id."""

    def __init__(
        self, policy_kinds: Iterable[QoSPolicyKind], *, callback: QosCallbackType | None = None,
        entity_id: str | None = None,
    ) -> None:
        self._policy_kinds = policy_kinds
        self._callback = callback
        self._entity_id = entity_id

    def __repr__(self) -> str:
        kinds = ", ".join(QoSPolicyKind(k).name for k in self._policy_kinds)
        return f"<QoSOverridingOptions {kinds or 'no policies'} entity_id={self._entity_id!r}>"

    @property
    def policy_kinds(self) -> Iterable[QoSPolicyKind]:
        return self._policy_kinds

    @property
    def callback(self) -> QosCallbackType | None:
        return self._callback

    @property
    def entity_id(self) -> str | None:
        return self._entity_id

    @classmethod
    def with_default_policies(
        cls, *, callback: QosCallbackType | None = None, entity_id: str | None = None
    ) -> QoSOverridingOptions:
        """History, depth and reliability, as rclpy's."""
        return cls(
            policy_kinds=(QoSPolicyKind.HISTORY, QoSPolicyKind.DEPTH, QoSPolicyKind.RELIABILITY),
            callback=callback, entity_id=entity_id,
        )


def declare_qos_parameters(
    entity_kind: str, node: Any, topic_name: str, qos: _qos.QoSProfile, options: QoSOverridingOptions | None
) -> _qos.QoSProfile:
    """The profile an entity of ``entity_kind`` ("publisher" or "subscription") on the resolved
    ``topic_name`` gets: ``qos`` with the overrides of ``options``' parameters applied, validated."""
    if options is None:
        return qos
    if not isinstance(options, QoSOverridingOptions):
        raise TypeError(f"qos_overriding_options: expected a QoSOverridingOptions, found {options!r}")
    profile = QoSProfile(**{name: getattr(qos, name) for name in qos.__dataclass_fields__})
    id_suffix = "" if options.entity_id is None else f"_{options.entity_id}"
    name = f"qos_overrides.{topic_name}.{entity_kind}{id_suffix}." "{}"
    description = "{}" f" for {entity_kind} `{topic_name}` with id `{options.entity_id}`"
    for policy in options.policy_kinds:
        policy = QoSPolicyKind(policy)
        if policy is QoSPolicyKind.LIFESPAN and entity_kind == "subscription":
            continue
        if policy is QoSPolicyKind.AVOID_ROS_NAMESPACE_CONVENTIONS:
            raise not_provided("rclpy.qos_overriding_options for QoSPolicyKind.AVOID_ROS_NAMESPACE_CONVENTIONS")
        policy_name = policy.name.lower()
        descriptor = _ri.ParameterDescriptor(description=description.format(policy_name), read_only=True)
        try:
            param = node.declare_parameter(name.format(policy_name), _parameter_value(profile, policy), descriptor)
        except ParameterAlreadyDeclaredError:
            param = node.get_parameter(name.format(policy_name))
        _override(profile, policy, param.value)
    if options.callback is not None:
        result = options.callback(profile)
        if not result.successful:
            raise InvalidQosOverridesError(
                f"{description.format('Provided QoS overrides')}, are not valid: {result.reason}"
            )
    return frozen(profile)  # type: ignore[no-any-return]


def _parameter_value(qos: Any, policy: QoSPolicyKind) -> str | int | bool:
    if policy is QoSPolicyKind.INVALID:
        raise AttributeError("'QoSProfile' object has no attribute 'invalid'")  # as rclpy's getattr fails
    value = getattr(qos, policy.name.lower())
    if isinstance(value, _qos.QoSPolicyEnum):
        return value.name.lower()
    if policy in _DURATIONS:
        return 0 if value is None else int(value.nanoseconds)  # rclpy's default Duration() is 0 ns
    return value  # type: ignore[no-any-return]


def _override(qos: Any, policy: QoSPolicyKind, value: Any) -> None:
    policy_name = policy.name.lower()
    if policy in _ENUMS:
        try:
            value = _ENUMS[policy][str(value).upper()]
        except KeyError:
            raise RuntimeError(f"Unexpected QoS override for policy `{policy_name}`: `{value}`") from None
    if policy in _DURATIONS:
        value = Duration(nanoseconds=value)
    setattr(qos, policy_name, value)
