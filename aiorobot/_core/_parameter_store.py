"""The parameters of one node, with rclpy's rules.

Declaring, setting and undeclaring all go through one atomic step: descriptors vet
the values (type, range, read-only), then the on-set callbacks, then the change is
committed, reported to the event hook (``/parameter_events``) and the post-set
callbacks run. Defaults and overrides go through it too, so a callback that rejects
a value rejects it at declaration as well (rclpy test_node.py::test_declare_parameter).

Callbacks may be ``async def``; the synchronous entry points then raise ``TypeError``
and point at their ``_async`` twins.
"""

from __future__ import annotations

import inspect
from collections.abc import Awaitable, Callable, Generator, Iterable, Mapping, Sequence
from typing import Any

from ._errors import (
    InvalidParameterTypeError,
    InvalidParameterValueError,
    ParameterAlreadyDeclaredError,
    ParameterImmutableError,
    ParameterNotDeclaredError,
    ParameterUninitializedError,
)
from ._parameter_types import (
    SEPARATOR,
    FloatingPointRange,
    IntegerRange,
    Parameter,
    ParameterDescriptor,
    ParameterType,
    SetParametersResult,
    as_descriptor,
    coerce,
    parameter_value_to_python,
)

__all__ = ["ParameterStore"]

OnSetCallback = Callable[[list[Parameter]], "SetParametersResult | Awaitable[SetParametersResult]"]
PreSetCallback = Callable[[list[Parameter]], "list[Parameter] | Awaitable[list[Parameter]]"]
PostSetCallback = Callable[[list[Parameter]], Any]
#: event hook: (new, changed, deleted) parameters of one committed change
EventHook = Callable[[list[Parameter], list[Parameter], list[Parameter]], None]

_WRONG_TYPE = "Wrong parameter type"  # rclpy's reason prefixes, which callers test


def _override_value(value: Any) -> Any:
    """An override as a plain value: a Parameter, a ParameterValue message, or the value itself."""
    if isinstance(value, Parameter):
        return value.value
    if getattr(value, "__msgtype__", None) == "rcl_interfaces/msg/ParameterValue":
        return parameter_value_to_python(value)
    return value


class ParameterStore:
    """The parameters of one node. ``owner`` names the node in messages."""

    def __init__(
        self,
        owner: str,
        overrides: Mapping[str, Any] | None = None,
        *,
        allow_undeclared: bool = False,
        quiet: set[str] | None = None,
        sources: Mapping[str, str] | None = None,
    ) -> None:
        self.owner = owner
        self._quiet = set(quiet or ())  # from files and -p: may name parameters never declared
        #: where a file or ``-p`` override was written, named in the error when it is refused
        self.sources: dict[str, str] = dict(sources or {})
        self.overrides: dict[str, Any] = {k: _override_value(v) for k, v in (overrides or {}).items()}
        self.allow_undeclared = allow_undeclared
        self.event_hook: EventHook | None = None
        self._values: dict[str, Parameter] = {}
        self._descriptors: dict[str, ParameterDescriptor] = {}
        self._pre: list[PreSetCallback] = []
        self._on: list[OnSetCallback] = []
        self._post: list[PostSetCallback] = []
        self._claimed: set[str] = set()

    def __repr__(self) -> str:
        return f"<ParameterStore of {self.owner}: {len(self._values)} parameters>"

    # -- declaration -----------------------------------------------------------------

    def declare(
        self,
        name: str,
        value: Any = None,
        descriptor: Any = None,
        ignore_override: bool = False,
        *,
        description: str = "",
        read_only: bool = False,
        range: Sequence[float] | None = None,
    ) -> Parameter:
        return self.declare_many(
            "",
            [(name, value, descriptor)],
            ignore_override,
            description=description,
            read_only=read_only,
            range=range,
        )[0]

    def declare_many(
        self,
        namespace: str,
        parameters: Iterable[Sequence[Any]],
        ignore_override: bool = False,
        *,
        description: str = "",
        read_only: bool = False,
        range: Sequence[float] | None = None,
    ) -> list[Parameter]:
        """rclpy's ``declare_parameters``: tuples ``(name,)``, ``(name, type_or_value)`` or
        ``(name, type_or_value, descriptor)``, names prefixed with ``namespace.``."""
        if not isinstance(namespace, str):
            raise TypeError(f"namespace: expected a str, found {namespace!r}")
        prepared: list[tuple[str, Any, ParameterDescriptor]] = []
        from_override: set[str] = set()
        for index, entry in enumerate(parameters):
            if not isinstance(entry, (tuple, list)) or not 1 <= len(entry) <= 3:
                raise TypeError(
                    f"parameter {index}: expected a tuple (name,), (name, value) or (name, value, descriptor), "
                    f"found {entry!r}"
                )
            name = entry[0]
            if not isinstance(name, str):
                raise TypeError(f"parameter {index}: the name must be a str, found {name!r}")
            if namespace:
                name = f"{namespace}{SEPARATOR}{name}"
            if not name:
                raise InvalidParameterValueError(name, "a parameter name must be a non-empty str")
            second = entry[1] if len(entry) > 1 else None
            given = entry[2] if len(entry) > 2 else None
            d = as_descriptor(given)
            if given is None:
                d.description = description
                d.read_only = read_only
            elif description or read_only:
                raise TypeError(
                    f"parameter {name!r}: give either a descriptor or the description/read_only keywords, not both"
                )
            if len(entry) == 1 or (second is None and given is None):
                d.dynamic_typing = True  # name only: rclpy's (deprecated) dynamically typed declaration
            value: Any = None
            if isinstance(second, ParameterType):
                if second is ParameterType.NOT_SET:
                    raise ValueError(f"cannot declare parameter {name!r} as statically typed of type NOT_SET")
                if d.dynamic_typing:
                    raise ValueError(
                        f"parameter {name!r}: a descriptor with dynamic_typing=True cannot go with a parameter type"
                    )
                d.type = second
            else:
                value = second if _is_value_msg(second) else _override_value(second)
                if not d.dynamic_typing:
                    if _is_value_msg(value):
                        d.type = ParameterType(value.type)
                    else:
                        try:
                            d.type = ParameterType.from_parameter_value(value)
                        except TypeError as err:
                            raise InvalidParameterValueError(name, f"bad default: {err}") from None
                    if d.type is ParameterType.NOT_SET:
                        raise ValueError(
                            f"cannot declare parameter {name!r} statically typed with no default value: "
                            "give a default, a Parameter.Type, or a descriptor with dynamic_typing=True"
                        )
            if not ignore_override and name in self.overrides:
                self._claimed.add(name)
                value = self.overrides[name]
                from_override.add(name)
            if _is_value_msg(value):
                raise ValueError(
                    f"parameter {name!r}: cannot declare from a ParameterValue message unless it is an override"
                )
            if range is not None:
                _apply_range_spec(name, d, range)
            d.name = name
            prepared.append((name, value, d))
        declared = [name for name, _, _ in prepared if name in self._values]
        if declared:
            raise ParameterAlreadyDeclaredError(
                f"parameter{'s' if len(declared) > 1 else ''} {', '.join(map(repr, declared))} "
                f"of {self.owner} already declared"
            )
        for name, value, d in prepared:
            if value is None:
                param = Parameter(name)
            else:
                ptype = d.type if not d.dynamic_typing else ParameterType.from_parameter_value(value)
                try:
                    param = Parameter(name, ptype, coerce(ptype, value))
                except TypeError as err:
                    raise InvalidParameterTypeError(name, self._from(name, str(err), from_override)) from None
            result = _drive(self._atomic([param], {name: d}, declaring=True), "declare_parameter")
            if not result.successful:
                reason = self._from(name, result.reason, from_override)
                if result.reason.startswith(_WRONG_TYPE):
                    raise InvalidParameterTypeError(name, reason)
                raise InvalidParameterValueError(name, reason)
        return [self._values[name] for name, _, _ in prepared]

    def _from(self, name: str, reason: str, from_override: set[str]) -> str:
        """``reason``, naming the file and key (or ``-p``) the refused override came from."""
        source = self.sources.get(name) if name in from_override else None
        return f"{reason} (from {source})" if source else reason

    def undeclare(self, name: str) -> None:
        if name not in self._values:
            raise ParameterNotDeclaredError(f"parameter {name!r} is not declared by {self.owner}")
        if self._descriptors[name].read_only:
            raise ParameterImmutableError(f"parameter {name!r} of {self.owner} is read-only and cannot be undeclared")
        param = self._values.pop(name)
        del self._descriptors[name]
        if self.event_hook is not None:
            self.event_hook([], [], [param])

    def set_descriptor(self, name: str, descriptor: Any, alternative_value: Any = None) -> Any:
        """rclpy's ``set_descriptor``: a new descriptor for a declared parameter; when the current
        value breaks it, ``alternative_value`` (a ParameterValue) replaces it or
        ``InvalidParameterValueError`` is raised. Returns the value as a ParameterValue."""
        if name not in self._values:
            if self.allow_undeclared:
                return self.get(name).get_parameter_value()
            raise self._not_declared(name)
        if self._descriptors[name].read_only:
            raise ParameterImmutableError(f"parameter {name!r} of {self.owner} is read-only; its descriptor is fixed")
        d = as_descriptor(descriptor)
        d.name = name
        current = self._values[name]
        result, value = self._vet(current, d, check_read_only=False)
        if not result.successful and alternative_value is not None:
            alternative = Parameter(name, ParameterType(alternative_value.type), parameter_value_to_python(alternative_value))
            result, value = self._vet(alternative, d, check_read_only=False)
        if not result.successful:
            raise InvalidParameterValueError(name, result.reason)
        if d.dynamic_typing:
            d.type = value.type_
        self._descriptors[name] = d
        self._values[name] = value
        return value.get_parameter_value()

    def unclaimed_overrides(self) -> list[str]:
        return sorted(set(self.overrides) - self._claimed - self._quiet)

    # -- reading -----------------------------------------------------------------------

    def has(self, name: str) -> bool:
        return name in self._values

    def names(self) -> list[str]:
        return sorted(self._values)

    def _not_declared(self, name: str) -> ParameterNotDeclaredError:
        return ParameterNotDeclaredError(
            f"parameter {name!r} is not declared by {self.owner} (declared: {', '.join(self.names()) or 'none'})"
        )

    def get(self, name: str) -> Parameter:
        param = self._values.get(name)
        if param is None:
            if self.allow_undeclared:
                return Parameter(name)
            raise self._not_declared(name)
        if param.type_ is ParameterType.NOT_SET and not self._descriptors[name].dynamic_typing:
            raise ParameterUninitializedError(
                f"parameter {name!r} of {self.owner} is declared as {self._descriptors[name].type.name} "
                "but has no value yet: give it an override or set it first"
            )
        return param

    def get_or(self, name: str, alternative: Parameter | None = None) -> Parameter:
        param = self._values.get(name)
        if param is None or param.type_ is ParameterType.NOT_SET:
            return alternative if alternative is not None else Parameter(name)
        return param

    def by_prefix(self, prefix: str) -> dict[str, Parameter]:
        if prefix:
            prefix += SEPARATOR
        return {name[len(prefix):]: p for name, p in self._values.items() if name.startswith(prefix)}

    def type_of(self, name: str) -> ParameterType:
        if name in self._values:
            return self._values[name].type_
        if self.allow_undeclared:
            return ParameterType.NOT_SET
        raise self._not_declared(name)

    def describe(self, name: str) -> ParameterDescriptor:
        d = self._descriptors.get(name)
        if d is None:
            if self.allow_undeclared:
                return ParameterDescriptor()
            raise self._not_declared(name)
        return as_descriptor(d)

    def list(self, prefixes: Sequence[str], depth: int) -> tuple[list[str], list[str]]:
        """rclpy's ``list_parameters``: (names, prefixes); depth 0 = recursive."""
        if not isinstance(prefixes, (list, tuple)) or not all(isinstance(p, str) for p in prefixes):
            raise TypeError(f"prefixes: expected a list of str, found {prefixes!r}")
        if isinstance(depth, bool) or not isinstance(depth, int):
            raise TypeError(f"depth: expected an int, found {depth!r}")
        if depth < 0:
            raise ValueError(f"depth: expected >= 0 (0 = recursive), found {depth}")

        def shallow(s: str) -> bool:
            return s.count(SEPARATOR) < depth

        recursive = not prefixes and depth == 0
        names: list[str] = []
        found_prefixes: list[str] = []
        for name in self._values:
            if not recursive:
                if not (not prefixes and shallow(name)) and not any(
                    name == prefix
                    or (name.startswith(prefix + SEPARATOR) and (depth == 0 or shallow(name[len(prefix) + 1 :])))
                    for prefix in prefixes
                ):
                    continue
            names.append(name)
            cut = name.rfind(SEPARATOR)
            if cut != -1 and name[:cut] not in found_prefixes:
                found_prefixes.append(name[:cut])
        return names, found_prefixes

    # -- callbacks -------------------------------------------------------------------------

    def add_pre_set_callback(self, callback: PreSetCallback) -> None:
        self._pre.insert(0, callback)

    def add_on_set_callback(self, callback: OnSetCallback) -> None:
        self._on.insert(0, callback)

    def add_post_set_callback(self, callback: PostSetCallback) -> None:
        self._post.insert(0, callback)

    def remove_pre_set_callback(self, callback: PreSetCallback) -> None:
        self._pre.remove(callback)

    def remove_on_set_callback(self, callback: OnSetCallback) -> None:
        self._on.remove(callback)

    def remove_post_set_callback(self, callback: PostSetCallback) -> None:
        self._post.remove(callback)

    # -- setting ------------------------------------------------------------------------------

    def set(self, params: Iterable[Parameter]) -> list[SetParametersResult]:
        """Each parameter on its own (rclpy's ``set_parameters``); an undeclared one raises
        ``ParameterNotDeclaredError`` once those before it are applied, unless undeclared
        parameters are allowed."""
        return [_drive(self._set_one([p]), "set_parameters") for p in _check_list(params)]

    async def set_async(self, params: Iterable[Parameter]) -> list[SetParametersResult]:
        return [await _drive_async(self._set_one([p])) for p in _check_list(params)]

    def set_atomically(self, params: Iterable[Parameter]) -> SetParametersResult:
        return _drive(self._set_one(_check_list(params)), "set_parameters_atomically")

    async def set_atomically_async(self, params: Iterable[Parameter]) -> SetParametersResult:
        return await _drive_async(self._set_one(_check_list(params)))

    def _set_one(self, params: list[Parameter]) -> Generator[Any, Any, SetParametersResult]:
        if self._pre:
            modified: list[Parameter] = []
            for cb in self._pre:
                modified.extend((yield cb(params)) or [])
            params = _check_list(modified)
            if not params:
                return SetParametersResult(
                    False,
                    "parameter list cannot be empty, this might be due to "
                    "pre_set_parameters_callback modifying the original parameters list.",  # rclpy's words
                )
        undeclared = [p.name for p in params if p.name not in self._values]
        if undeclared and not self.allow_undeclared:
            raise ParameterNotDeclaredError(
                f"parameter{'s' if len(undeclared) > 1 else ''} {', '.join(map(repr, undeclared))} "
                f"not declared by {self.owner} (declared: {', '.join(self.names()) or 'none'})"
            )
        return (yield from self._atomic(params, None, declaring=False))

    def _vet(
        self, param: Parameter, d: ParameterDescriptor | None, *, check_read_only: bool
    ) -> tuple[SetParametersResult, Parameter]:
        if d is None:  # an undeclared parameter, allowed: dynamically typed
            return SetParametersResult(True), param
        if check_read_only and d.read_only:
            return SetParametersResult(False, f"parameter {param.name!r} is read-only"), param
        if d.dynamic_typing:
            return SetParametersResult(True), param
        if param.type_ is ParameterType.NOT_SET:
            if param.name in self._values:
                return SetParametersResult(False, f"Static parameter cannot be undeclared ({param.name!r})"), param
            return SetParametersResult(True), param  # typed declaration without a value
        try:
            value = coerce(d.type, param.value)
        except TypeError as err:
            return SetParametersResult(False, f"{_WRONG_TYPE} for {param.name!r}: {err}"), param
        coerced = Parameter(param.name, d.type, value)
        problem = d.check_range(value)
        if problem:
            return SetParametersResult(False, problem), coerced
        return SetParametersResult(True), coerced

    def _atomic(
        self,
        params: list[Parameter],
        descriptors: dict[str, ParameterDescriptor] | None,
        *,
        declaring: bool,
    ) -> Generator[Any, Any, SetParametersResult]:
        vetted: list[Parameter] = []
        for param in params:
            d = (descriptors or self._descriptors).get(param.name)
            result, param = self._vet(param, d, check_read_only=not declaring)
            if not result.successful:
                return result
            vetted.append(param)
        for cb in list(self._on):
            verdict = yield cb(vetted)
            if not isinstance(verdict, SetParametersResult) and not hasattr(verdict, "successful"):
                raise TypeError(f"an on-set-parameters callback must return a SetParametersResult, got {verdict!r}")
            if not verdict.successful:
                return SetParametersResult(False, verdict.reason or "rejected by an on-set-parameters callback")
        new: list[Parameter] = []
        changed: list[Parameter] = []
        deleted: list[Parameter] = []
        for param in vetted:
            if param.type_ is ParameterType.NOT_SET and not declaring:
                deleted.append(param)  # rclpy: setting NOT_SET undeclares (dynamic parameters)
                self._values.pop(param.name, None)
                self._descriptors.pop(param.name, None)
                continue
            if descriptors is not None:
                d = descriptors[param.name]
                if d.dynamic_typing:
                    d.type = param.type_
                self._descriptors[param.name] = d
            elif param.name not in self._descriptors:
                self._descriptors[param.name] = ParameterDescriptor(name=param.name, dynamic_typing=True)
            elif self._descriptors[param.name].dynamic_typing:
                self._descriptors[param.name].type = param.type_
            previous = self._values.get(param.name)
            (new if previous is None or previous.type_ is ParameterType.NOT_SET else changed).append(param)
            self._values[param.name] = param
        if self.event_hook is not None:
            self.event_hook(new, changed, deleted)
        for cb in list(self._post):
            yield cb(vetted)
        return SetParametersResult(True)


def _is_value_msg(value: Any) -> bool:
    return getattr(value, "__msgtype__", None) == "rcl_interfaces/msg/ParameterValue"


def _check_list(params: Iterable[Parameter]) -> list[Parameter]:
    params = list(params)
    for p in params:
        if not isinstance(p, Parameter):
            raise TypeError(f"expected aiorobot.Parameter objects, found {p!r}")
    return params


def _drive(steps: Generator[Any, Any, SetParametersResult], what: str) -> SetParametersResult:
    """Run a set step synchronously; an awaitable callback result is an error naming the async twin."""
    try:
        verdict = next(steps)
        while True:
            if inspect.isawaitable(verdict):
                close = getattr(verdict, "close", None)
                if close is not None:
                    close()
                steps.close()
                raise TypeError(
                    f"an async parameters callback is registered: {what} cannot await it; "
                    f"use `await node.{what}_async(...)`"
                    if what != "declare_parameter"
                    else "an async parameters callback is registered: declare parameters before adding it"
                )
            verdict = steps.send(verdict)
    except StopIteration as done:
        result: SetParametersResult = done.value
        return result


async def _drive_async(steps: Generator[Any, Any, SetParametersResult]) -> SetParametersResult:
    try:
        verdict = next(steps)
        while True:
            verdict = steps.send(await verdict if inspect.isawaitable(verdict) else verdict)
    except StopIteration as done:
        result: SetParametersResult = done.value
        return result


def _apply_range_spec(name: str, d: ParameterDescriptor, spec: Sequence[float]) -> None:
    """aiorobot's ``range=(from, to[, step])`` as the descriptor's integer or floating-point range."""
    if d.type not in (ParameterType.INTEGER, ParameterType.DOUBLE):
        raise InvalidParameterValueError(
            name, f"a range needs an integer or double parameter, not {d.type.name.lower()}"
        )
    values = tuple(spec)
    if len(values) not in (2, 3) or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values):
        raise InvalidParameterValueError(name, f"range: expected (from, to) or (from, to, step), found {spec!r}")
    lo, hi = values[0], values[1]
    step = values[2] if len(values) == 3 else 0
    if lo > hi or step < 0:
        raise InvalidParameterValueError(name, f"range: expected from <= to and step >= 0, found {spec!r}")
    d.range = (lo, hi, step)
    if d.type is ParameterType.INTEGER:
        d.integer_range = (IntegerRange(lo, hi, step),)  # type: ignore[arg-type]
    else:
        d.floating_point_range = (FloatingPointRange(float(lo), float(hi), float(step)),)
