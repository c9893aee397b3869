"""Node parameters with ROS 2 semantics: declared, typed, ranged, read-only, vetted by callbacks.

A parameter's type is fixed by its default (or by its first value when declared
without one); an int is accepted where a double is declared, as TOML users
expect. A rejected value (wrong type, out of range, read-only, refused by a
callback) leaves the old value in place and the result says why.
"""

from __future__ import annotations

import enum
import inspect
import math
from collections.abc import Awaitable, Callable, Generator, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

from ._errors import (
    InvalidParameterValueError,
    ParameterAlreadyDeclaredError,
    ParameterNotDeclaredError,
)

__all__ = [
    "Parameter",
    "ParameterDescriptor",
    "ParameterStore",
    "ParameterType",
    "SetParametersResult",
]


class ParameterType(enum.IntEnum):
    """Values as ``rcl_interfaces/msg/ParameterType``."""

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
    def of(cls, value: Any) -> ParameterType:
        """The type of a Python value, or raise TypeError for unsupported values."""
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
        if isinstance(value, (list, tuple)):
            if not value:
                raise TypeError("an empty list has no element type; give a typed default")
            kinds = {cls.of(v) for v in value}
            if kinds == {cls.BOOL}:
                return cls.BOOL_ARRAY
            if kinds == {cls.INTEGER}:
                return cls.INTEGER_ARRAY
            if kinds <= {cls.INTEGER, cls.DOUBLE}:
                return cls.DOUBLE_ARRAY
            if kinds == {cls.STRING}:
                return cls.STRING_ARRAY
            raise TypeError(f"a list parameter must hold one type, found {sorted(k.name for k in kinds)}")
        if hasattr(value, "tolist"):  # numpy arrays and scalars
            return cls.of(value.tolist())
        raise TypeError(
            f"unsupported parameter value {value!r} of type {type(value).__name__} "
            "(bool, int, float, str, bytes or a list of one of them)"
        )


def _coerce(ptype: ParameterType, value: Any) -> Any:
    """Convert ``value`` to ``ptype`` where that loses nothing (int -> double); else TypeError."""
    found = ParameterType.of(value)
    if found is ptype:
        if ptype in (ParameterType.BOOL_ARRAY, ParameterType.INTEGER_ARRAY, ParameterType.STRING_ARRAY):
            return list(value)
        if ptype is ParameterType.DOUBLE_ARRAY:
            return [float(v) for v in value]
        if ptype is ParameterType.BYTE_ARRAY:
            return bytes(value)
        return value.tolist() if hasattr(value, "tolist") else value
    if ptype is ParameterType.DOUBLE and found is ParameterType.INTEGER:
        return float(value)
    if ptype is ParameterType.DOUBLE_ARRAY and found is ParameterType.INTEGER_ARRAY:
        return [float(v) for v in value]
    raise TypeError(f"expected {ptype.name.lower()}, found {found.name.lower()} {value!r}")


@dataclass(frozen=True, slots=True)
class Parameter:
    """A parameter name and value; the type follows from the value."""

    name: str
    value: Any = None

    @property
    def type_(self) -> ParameterType:
        return ParameterType.of(self.value)


@dataclass(frozen=True, slots=True)
class SetParametersResult:
    successful: bool
    reason: str = ""


@dataclass(frozen=True, slots=True)
class ParameterDescriptor:
    """What a node says about one parameter: type, description, limits."""

    name: str
    type: ParameterType
    description: str = ""
    read_only: bool = False
    range: tuple[float, float, float] | None = None  # (from, to, step); step 0 = any value

    def check_range(self, value: Any) -> str | None:
        if self.range is None or self.type not in (ParameterType.INTEGER, ParameterType.DOUBLE):
            return None
        lo, hi, step = self.range
        if not (lo <= value <= hi) and not (
            self.type is ParameterType.DOUBLE and (math.isclose(value, lo) or math.isclose(value, hi))
        ):
            return f"value {value!r} is outside the range [{lo}, {hi}]"
        if step:
            n = (value - lo) / step
            if value != hi and not math.isclose(n, round(n), abs_tol=1e-9):
                return f"value {value!r} is not {lo} plus a multiple of the step {step}"
        return None


OnSetCallback = Callable[[list[Parameter]], "SetParametersResult | Awaitable[SetParametersResult]"]


@dataclass
class _Entry:
    descriptor: ParameterDescriptor
    value: Any


@dataclass
class ParameterStore:
    """The parameters of one node. ``owner`` names the node in messages."""

    owner: str
    overrides: Mapping[str, Any] = field(default_factory=dict)
    _entries: dict[str, _Entry] = field(default_factory=dict)
    _callbacks: list[OnSetCallback] = field(default_factory=list)
    _claimed: set[str] = field(default_factory=set)

    def declare(
        self,
        name: str,
        default: Any = None,
        *,
        description: str = "",
        read_only: bool = False,
        range: Sequence[float] | None = None,
    ) -> Parameter:
        if not isinstance(name, str) or not name:
            raise InvalidParameterValueError(str(name), "a parameter name must be a non-empty str")
        if name in self._entries:
            raise ParameterAlreadyDeclaredError(f"parameter {name!r} of {self.owner} is already declared")
        try:
            ptype = ParameterType.of(default)
        except TypeError as err:
            raise InvalidParameterValueError(name, f"bad default: {err}") from None
        value = default
        if name in self.overrides:
            self._claimed.add(name)
            override = self.overrides[name]
            if ptype is ParameterType.NOT_SET:
                try:
                    ptype = ParameterType.of(override)
                except TypeError as err:
                    raise InvalidParameterValueError(name, str(err)) from None
            try:
                value = _coerce(ptype, override)
            except TypeError as err:
                raise InvalidParameterValueError(name, str(err)) from None
        elif ptype is not ParameterType.NOT_SET:
            value = _coerce(ptype, default)
        descriptor = ParameterDescriptor(
            name=name,
            type=ptype,
            description=description,
            read_only=read_only,
            range=_check_range_spec(name, range, ptype),
        )
        if value is not None:
            problem = descriptor.check_range(value)
            if problem:
                raise InvalidParameterValueError(name, problem)
        self._entries[name] = _Entry(descriptor, value)
        return Parameter(name, value)

    def unclaimed_overrides(self) -> list[str]:
        return sorted(set(self.overrides) - self._claimed)

    def has(self, name: str) -> bool:
        return name in self._entries

    def names(self) -> list[str]:
        return sorted(self._entries)

    def get(self, name: str) -> Parameter:
        entry = self._entries.get(name)
        if entry is None:
            raise ParameterNotDeclaredError(
                f"parameter {name!r} is not declared by {self.owner}"
                f" (declared: {', '.join(self.names()) or 'none'})"
            )
        return Parameter(name, entry.value)

    def describe(self, name: str) -> ParameterDescriptor:
        self.get(name)
        return self._entries[name].descriptor

    def add_callback(self, callback: OnSetCallback) -> OnSetCallback:
        self._callbacks.append(callback)
        return callback

    def remove_callback(self, callback: OnSetCallback) -> None:
        self._callbacks.remove(callback)

    def _vet(self, param: Parameter) -> tuple[SetParametersResult, Any]:
        entry = self._entries.get(param.name)
        if entry is None:
            return SetParametersResult(False, f"parameter {param.name!r} is not declared"), None
        d = entry.descriptor
        if d.read_only:
            return SetParametersResult(False, f"parameter {param.name!r} is read-only"), None
        ptype = d.type if d.type is not ParameterType.NOT_SET else None
        try:
            value = _coerce(ptype, param.value) if ptype is not None else param.value
            if ptype is None:
                ParameterType.of(value)
        except TypeError as err:
            return SetParametersResult(False, f"parameter {param.name!r}: {err}"), None
        problem = d.check_range(value)
        if problem:
            return SetParametersResult(False, f"parameter {param.name!r}: {problem}"), None
        return SetParametersResult(True), value

    def _commit(self, name: str, value: Any) -> None:
        entry = self._entries[name]
        if entry.descriptor.type is ParameterType.NOT_SET and value is not None:
            entry.descriptor = _replace_type(entry.descriptor, ParameterType.of(value))
        entry.value = value

    def _set_steps(self, params: Iterable[Parameter]) -> Generator[Any, SetParametersResult, list[SetParametersResult]]:
        """Set each parameter on its own; yields each callback's verdict and is sent it back resolved."""
        results = []
        for param in params:
            result, value = self._vet(param)
            if result.successful:
                for cb in self._callbacks:
                    verdict = yield cb([Parameter(param.name, value)])
                    if not verdict.successful:
                        result = SetParametersResult(False, verdict.reason or "rejected by a callback")
                        break
            if result.successful:
                self._commit(param.name, value)
            results.append(result)
        return results

    def set(self, params: Iterable[Parameter]) -> list[SetParametersResult]:
        """Set each parameter on its own (not atomically), as ``rclpy.Node.set_parameters``."""
        steps = self._set_steps(params)
        try:
            verdict = next(steps)
            while True:
                if inspect.isawaitable(verdict):
                    _close(verdict)
                    steps.close()
                    raise TypeError(
                        "an async on-set-parameters callback is registered: "
                        "use `await node.set_parameters_async(...)`"
                    )
                verdict = steps.send(verdict)
        except StopIteration as done:
            return done.value

    async def set_async(self, params: Iterable[Parameter]) -> list[SetParametersResult]:
        """Like :meth:`set`, awaiting async callbacks."""
        steps = self._set_steps(params)
        try:
            verdict = next(steps)
            while True:
                verdict = steps.send(await verdict if inspect.isawaitable(verdict) else verdict)
        except StopIteration as done:
            return done.value


def _close(awaitable: Any) -> None:
    close = getattr(awaitable, "close", None)
    if close is not None:
        close()


def _replace_type(d: ParameterDescriptor, ptype: ParameterType) -> ParameterDescriptor:
    return ParameterDescriptor(d.name, ptype, d.description, d.read_only, d.range)


def _check_range_spec(
    name: str, spec: Sequence[float] | None, ptype: ParameterType
) -> tuple[float, float, float] | None:
    if spec is None:
        return None
    if ptype not in (ParameterType.INTEGER, ParameterType.DOUBLE):
        raise InvalidParameterValueError(name, f"a range needs an integer or double parameter, not {ptype.name.lower()}")
    values = tuple(spec)
    if len(values) not in (2, 3) or not all(
        isinstance(v, (int, float)) and not isinstance(v, bool) for v in values
    ):
        raise InvalidParameterValueError(name, f"range: expected (from, to) or (from, to, step), found {spec!r}")
    lo, hi = values[0], values[1]
    step = values[2] if len(values) == 3 else 0
    if lo > hi or step < 0:
        raise InvalidParameterValueError(name, f"range: expected from <= to and step >= 0, found {spec!r}")
    return (lo, hi, step)
