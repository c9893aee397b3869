"""Parameter values as rclpy has them: ``Parameter``, its ``Type``, descriptors, ranges, and the
conversions to and from ``rcl_interfaces`` messages.

The node-side rules (declaration, overrides, callbacks, events) live in
:mod:`aiorobot._core._parameter_store`.
"""

from __future__ import annotations

import array
import enum
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

__all__ = [
    "FloatingPointRange",
    "IntegerRange",
    "Parameter",
    "ParameterDescriptor",
    "ParameterType",
    "SetParametersResult",
    "get_parameter_value",
    "parameter_value_to_python",
]

#: rclpy's ``PARAMETER_SEPARATOR_STRING``
SEPARATOR = "."


class ParameterType(enum.IntEnum):
    """Values as ``rcl_interfaces/msg/ParameterType``; also ``Parameter.Type``.

    rclpy difference: ``bytes`` is a BYTE_ARRAY value, a list mixing ints and floats is a
    DOUBLE_ARRAY (rclpy raises ``TypeError``), and an empty list fits any array type (rclpy
    calls it a BYTE_ARRAY, so it cannot be set on a string-array parameter).
    """

    NOT_SET = 0
    BOOL = 1
    INTEGER = 2
    DOUBLE = 3
    STRING = 4
    BYTE_ARRAY = 5
    BOOL_ARRAY = 6
    INTEGER_ARRAY = 7
    DOUBLE_ARRAY = 8
    STRING_ARRAY = 9

    @classmethod
    def from_parameter_value(cls, value: Any) -> ParameterType:
        """The type of a Python value (rclpy's rules), or ``TypeError`` for unsupported values.

        A list of ``bytes`` is a BYTE_ARRAY (so is ``bytes``); an empty list is a
        BYTE_ARRAY as in rclpy, and is accepted for any array parameter.
        """
        if value is None:
            return cls.NOT_SET
        if isinstance(value, bool):
            return cls.BOOL
        if isinstance(value, int):
            return cls.INTEGER
        if isinstance(value, float):
            return cls.DOUBLE
        if isinstance(value, str):
            return cls.STRING
        if isinstance(value, (bytes, bytearray)):
            return cls.BYTE_ARRAY
        if hasattr(value, "tolist") and not isinstance(value, array.array):  # numpy arrays and scalars
            return cls.from_parameter_value(value.tolist())
        if isinstance(value, (list, tuple, array.array)):
            if all(isinstance(v, bytes) for v in value):
                return cls.BYTE_ARRAY
            if all(isinstance(v, bool) for v in value):
                return cls.BOOL_ARRAY
            if all(isinstance(v, int) and not isinstance(v, bool) for v in value):
                return cls.INTEGER_ARRAY
            if all(isinstance(v, float) for v in value):
                return cls.DOUBLE_ARRAY
            if all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value):
                return cls.DOUBLE_ARRAY  # [1, 2.5]: what a TOML or YAML user means
            if all(isinstance(v, str) for v in value):
                return cls.STRING_ARRAY
            raise TypeError(f"a list parameter must hold one type (bool, int, float, str or bytes), found {value!r}")
        raise TypeError(
            f"unsupported parameter value {value!r} of type {type(value).__name__} "
            "(bool, int, float, str, or a list of bytes, bool, int, float or str)"
        )

    #: aiorobot's shorter name for :meth:`from_parameter_value`
    of = from_parameter_value

    def check(self, value: Any) -> bool:
        """Whether ``value`` is of this type, as rclpy's ``Parameter.Type.check``."""
        try:
            found = ParameterType.from_parameter_value(value)
        except TypeError:
            return False
        return found is self or (
            isinstance(value, (list, tuple)) and not value and self >= ParameterType.BYTE_ARRAY
        )


def _normalise(ptype: ParameterType, value: Any) -> Any:
    """The stored form: lists for arrays (BYTE_ARRAY as a list of one-byte ``bytes``), plain scalars."""
    if ptype is ParameterType.BYTE_ARRAY:
        if isinstance(value, (bytes, bytearray)):
            return [bytes([b]) for b in value]
        return [bytes(v) for v in value]
    if ptype is ParameterType.DOUBLE_ARRAY:
        return [float(v) for v in (value.tolist() if hasattr(value, "tolist") else value)]
    if ptype >= ParameterType.BOOL_ARRAY:
        return list(value.tolist() if hasattr(value, "tolist") else value)
    if hasattr(value, "tolist"):
        return value.tolist()
    return value


def coerce(ptype: ParameterType, value: Any) -> Any:
    """``value`` as a value of ``ptype`` where that loses nothing (int -> double); else ``TypeError``."""
    found = ParameterType.from_parameter_value(value)
    if found is ptype:
        return _normalise(ptype, value)
    if ptype is ParameterType.DOUBLE and found is ParameterType.INTEGER:
        return float(value)
    if ptype is ParameterType.DOUBLE_ARRAY and found is ParameterType.INTEGER_ARRAY:
        return [float(v) for v in value]
    if ptype >= ParameterType.BYTE_ARRAY and isinstance(value, (list, tuple)) and not value:
        return []
    raise TypeError(f"expected {ptype.name.lower()}, found {found.name.lower()} {value!r}")


class Parameter:
    """A parameter name, type and value, as rclpy's ``Parameter``.

    ``Parameter(name, Parameter.Type.INTEGER, 42)``, ``Parameter(name, value=42)`` and
    ``Parameter(name)`` (NOT_SET) work as in rclpy: a value that disagrees with the given
    type raises ``ValueError``, an unsupported value ``TypeError``.

    rclpy difference: ``Parameter(name, 42)`` (a second argument that is not a
    ``Parameter.Type``, and no third) means ``value=42``, aiorobot's two-argument form;
    rclpy raises ``TypeError`` there.
    """

    __slots__ = ("_name", "_type", "_value")

    Type = ParameterType

    def __init__(self, name: str, type_: Any = None, value: Any = None) -> None:
        if type_ is not None and not isinstance(type_, ParameterType):
            if value is not None:
                raise TypeError(f"type_: expected a Parameter.Type, found {type_!r}")
            type_, value = None, type_  # aiorobot's Parameter(name, value)
        if type_ is None:
            type_ = ParameterType.from_parameter_value(value)
        elif not type_.check(value):
            raise ValueError(f"type {type_.name} and value {value!r} do not agree (parameter {name!r})")
        self._name = name
        self._type = type_
        self._value = value

    @property
    def name(self) -> str:
        return self._name

    @property
    def type_(self) -> ParameterType:
        return self._type

    @property
    def value(self) -> Any:
        return self._value

    def __repr__(self) -> str:
        return f"Parameter({self._name!r}, {self._type.name}, {self._value!r})"

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Parameter):
            return NotImplemented
        return (self._name, self._type, self._value) == (other._name, other._type, other._value)

    __hash__ = None  # type: ignore[assignment]  # values may be lists

    def get_parameter_value(self) -> Any:
        """This value as an ``rcl_interfaces/msg/ParameterValue``."""
        return to_parameter_value(self._type, self._value)

    def to_parameter_msg(self) -> Any:
        """This parameter as an ``rcl_interfaces/msg/Parameter``."""
        from ..msgs.rcl_interfaces import Parameter as ParameterMsg

        return ParameterMsg(name=self._name, value=self.get_parameter_value())

    @classmethod
    def from_parameter_msg(cls, msg: Any) -> Parameter:
        """From an ``rcl_interfaces/msg/Parameter``."""
        value = parameter_value_to_python(msg.value)
        return cls(msg.name, ParameterType(msg.value.type), value)


_FIELDS = {
    ParameterType.BOOL: "bool_value",
    ParameterType.INTEGER: "integer_value",
    ParameterType.DOUBLE: "double_value",
    ParameterType.STRING: "string_value",
    ParameterType.BYTE_ARRAY: "byte_array_value",
    ParameterType.BOOL_ARRAY: "bool_array_value",
    ParameterType.INTEGER_ARRAY: "integer_array_value",
    ParameterType.DOUBLE_ARRAY: "double_array_value",
    ParameterType.STRING_ARRAY: "string_array_value",
}


def to_parameter_value(ptype: ParameterType, value: Any) -> Any:
    """``value`` of ``ptype`` as an ``rcl_interfaces/msg/ParameterValue``."""
    from ..msgs.rcl_interfaces import ParameterValue

    if ptype is ParameterType.NOT_SET:
        return ParameterValue(type=0)
    if ptype is ParameterType.BYTE_ARRAY:
        value = list(b"".join(_normalise(ptype, value)))
    elif ptype >= ParameterType.BOOL_ARRAY:
        value = _normalise(ptype, value)
    return ParameterValue(type=int(ptype), **{_FIELDS[ptype]: value})


def parameter_value_to_python(parameter_value: Any) -> Any:
    """The Python value of an ``rcl_interfaces/msg/ParameterValue`` (``None`` for NOT_SET).

    Raises ``RuntimeError`` for an unknown ``type``, as rclpy.
    """
    try:
        ptype = ParameterType(parameter_value.type)
    except ValueError:
        raise RuntimeError(f"unexpected parameter type {parameter_value.type}") from None
    if ptype is ParameterType.NOT_SET:
        return None
    value = getattr(parameter_value, _FIELDS[ptype])
    if ptype is ParameterType.BYTE_ARRAY:
        return [bytes([int(b)]) for b in value]
    if ptype >= ParameterType.BOOL_ARRAY:
        return list(value.tolist() if hasattr(value, "tolist") else value)
    return value.item() if hasattr(value, "item") else value


def get_parameter_value(string_value: str) -> Any:
    """Guess a ``ParameterValue`` from text, as rclpy's (and ``ros2 param set``/``-p name:=value``):
    YAML scalars and flow lists keep their type, anything else is a string."""
    import yaml

    try:
        loaded = yaml.safe_load(string_value)
    except yaml.YAMLError:
        loaded = string_value
    if isinstance(loaded, (bool, int, float)):
        return to_parameter_value(ParameterType.from_parameter_value(loaded), loaded)
    if isinstance(loaded, list):
        if not loaded:
            return to_parameter_value(ParameterType.BOOL_ARRAY, [])  # rclpy: all() of nothing is true
        try:
            ptype = ParameterType.from_parameter_value(loaded)
        except TypeError:
            ptype = ParameterType.STRING
        if ptype in (
            ParameterType.BOOL_ARRAY,
            ParameterType.INTEGER_ARRAY,
            ParameterType.DOUBLE_ARRAY,
            ParameterType.STRING_ARRAY,
        ):
            if ptype is ParameterType.DOUBLE_ARRAY and not all(isinstance(v, float) for v in loaded):
                ptype = ParameterType.STRING  # rclpy: a mixed int/float list stays text
            else:
                return to_parameter_value(ptype, loaded)
        return to_parameter_value(ParameterType.STRING, string_value)
    text = loaded if isinstance(loaded, str) else string_value
    return to_parameter_value(ParameterType.STRING, text)


@dataclass(frozen=True, slots=True)
class SetParametersResult:
    """The outcome of setting parameters: ``successful`` and, when not, the ``reason``."""

    successful: bool
    reason: str = ""


@dataclass(frozen=True, slots=True)
class IntegerRange:
    """Allowed integers: ``from_value`` to ``to_value`` inclusive, on multiples of ``step`` (0: any)."""

    from_value: int
    to_value: int
    step: int = 0


@dataclass(frozen=True, slots=True)
class FloatingPointRange:
    """Allowed doubles: ``from_value`` to ``to_value`` inclusive, on multiples of ``step`` (0: any)."""

    from_value: float
    to_value: float
    step: float = 0.0


#: rclpy's tolerance for floating-point range edges and steps
PARAM_REL_TOL = 1e-6


@dataclass(slots=True)
class ParameterDescriptor:
    """What a node says about one parameter, as ``rcl_interfaces/msg/ParameterDescriptor``.

    ``range`` is aiorobot's shorthand, ``(from, to)`` or ``(from, to, step)``; a declaration
    turns it into ``integer_range`` or ``floating_point_range`` by the parameter's type.
    """

    name: str = ""
    type: ParameterType = ParameterType.NOT_SET
    description: str = ""
    read_only: bool = False
    range: tuple[float, float, float] | None = None
    additional_constraints: str = ""
    dynamic_typing: bool = False
    integer_range: Sequence[Any] = field(default_factory=tuple)
    floating_point_range: Sequence[Any] = field(default_factory=tuple)

    @classmethod
    def from_msg(cls, msg: Any) -> ParameterDescriptor:
        """From an ``rcl_interfaces/msg/ParameterDescriptor``."""
        return cls(
            name=msg.name,
            type=ParameterType(msg.type),
            description=msg.description,
            read_only=bool(msg.read_only),
            additional_constraints=msg.additional_constraints,
            dynamic_typing=bool(msg.dynamic_typing),
            integer_range=tuple(IntegerRange(int(r.from_value), int(r.to_value), int(r.step)) for r in msg.integer_range),
            floating_point_range=tuple(
                FloatingPointRange(float(r.from_value), float(r.to_value), float(r.step)) for r in msg.floating_point_range
            ),
        )

    def to_msg(self) -> Any:
        """As an ``rcl_interfaces/msg/ParameterDescriptor``."""
        from ..msgs import rcl_interfaces as ri

        return ri.ParameterDescriptor(
            name=self.name,
            type=int(self.type),
            description=self.description,
            additional_constraints=self.additional_constraints,
            read_only=self.read_only,
            dynamic_typing=self.dynamic_typing,
            integer_range=[
                ri.IntegerRange(from_value=int(r.from_value), to_value=int(r.to_value), step=int(r.step))
                for r in self.integer_range
            ],
            floating_point_range=[
                ri.FloatingPointRange(from_value=float(r.from_value), to_value=float(r.to_value), step=float(r.step))
                for r in self.floating_point_range
            ],
        )

    def check_range(self, value: Any) -> str | None:
        """Why ``value`` lies outside this descriptor's range, or ``None`` (rclpy's edge and step rules)."""
        if self.type is ParameterType.INTEGER and self.integer_range and isinstance(value, int):
            r = self.integer_range[0]
            lo, hi = min(r.from_value, r.to_value), max(r.from_value, r.to_value)
            if value in (lo, hi):
                return None
            if not lo < value < hi:
                return f"value {value!r} is outside the range [{lo}, {hi}]"
            if r.step and (value - lo) % r.step:
                return f"value {value!r} is not {lo} plus a multiple of the step {r.step}"
            return None
        if self.type is ParameterType.DOUBLE and self.floating_point_range and isinstance(value, float):
            r = self.floating_point_range[0]
            lo, hi = min(r.from_value, r.to_value), max(r.from_value, r.to_value)
            if math.isclose(value, lo, rel_tol=PARAM_REL_TOL) or math.isclose(value, hi, rel_tol=PARAM_REL_TOL):
                return None
            if not lo < value < hi:
                return f"value {value!r} is outside the range [{lo}, {hi}]"
            if r.step:
                steps = round((value - lo) / r.step)
                if not math.isclose(lo + steps * r.step, value, rel_tol=PARAM_REL_TOL):
                    return f"value {value!r} is not {lo} plus a multiple of the step {r.step}"
        return None


def as_descriptor(descriptor: Any) -> ParameterDescriptor:
    """A copy of ``descriptor`` (ours or an ``rcl_interfaces`` message); ``TypeError`` otherwise."""
    if descriptor is None:
        return ParameterDescriptor()
    if isinstance(descriptor, ParameterDescriptor):
        return ParameterDescriptor(
            descriptor.name,
            ParameterType(descriptor.type),
            descriptor.description,
            descriptor.read_only,
            descriptor.range,
            descriptor.additional_constraints,
            descriptor.dynamic_typing,
            tuple(descriptor.integer_range),
            tuple(descriptor.floating_point_range),
        )
    if getattr(descriptor, "__msgtype__", None) == "rcl_interfaces/msg/ParameterDescriptor":
        return ParameterDescriptor.from_msg(descriptor)
    raise TypeError(f"descriptor: expected a ParameterDescriptor, found {descriptor!r}")
