"""The parameter methods of ``Node`` (rclpy's names and rules), composed over a ``ParameterStore``."""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from typing import Any

from ._parameter_store import OnSetCallback, ParameterStore, PostSetCallback, PreSetCallback
from ._parameter_types import Parameter, ParameterDescriptor, ParameterType, SetParametersResult

__all__ = ["NodeParametersMixin"]


class NodeParametersMixin:
    """rclpy's parameter methods; the node owns one :class:`ParameterStore` as ``_parameters``."""

    _parameters: ParameterStore

    def _setup_parameters(self, auto_declare: bool, start_services: bool) -> None:
        """``/parameter_events``, the node's ``use_sim_time`` and, unless told not to, its parameter services."""
        from ._parameter_services import ParameterEventPublisher, create_parameter_services
        from ._time_source import TimeSource

        self._parameters.event_hook = ParameterEventPublisher(self)  # type: ignore[arg-type]
        if auto_declare:
            overrides = self._parameters.overrides
            self.declare_parameters("", [(n, v) for n, v in overrides.items()], ignore_override=True)
            self._parameters._claimed.update(overrides)
        self._time_source = TimeSource(self)  # type: ignore[arg-type]
        if start_services:
            create_parameter_services(self)  # type: ignore[arg-type]

    def declare_parameter(
        self,
        name: str,
        value: Any = None,
        descriptor: Any = None,
        ignore_override: bool = False,
        *,
        description: str = "",
        read_only: bool = False,
        range: Iterable[float] | None = None,
        default: Any = None,
    ) -> Parameter:
        """Declare a parameter; an override given to the node replaces ``value``.

        ``value`` is the default, or a ``Parameter.Type`` for a typed parameter without
        one (reading it before it has a value raises ``ParameterUninitializedError``);
        ``declare_parameter(name)`` alone declares a dynamically typed parameter.
        ``descriptor`` is a :class:`ParameterDescriptor` (or the ``rcl_interfaces``
        message); ``default=`` is another name for ``value``; the keywords ``description``, ``read_only`` and ``range``
        (``(from, to)`` or ``(from, to, step)``) are aiorobot's shorthand for it.
        The value goes through the same checks and on-set callbacks as a set:
        ``InvalidParameterTypeError`` for a wrong type, ``InvalidParameterValueError``
        for a value out of range or rejected by a callback.

        rclpy difference: an int is accepted for a double parameter (and int lists for
        double arrays), as TOML and YAML users write ``2`` for ``2.0``; declaring with only a
        name does not warn.
        """
        if default is not None:  # API.md's name for the value
            if value is not None:
                raise TypeError(f"declare_parameter({name!r}): give value or default, not both")
            value = default
        return self._parameters.declare(
            name,
            value,
            descriptor,
            ignore_override,
            description=description,
            read_only=read_only,
            range=tuple(range) if range is not None else None,
        )

    def declare_parameters(
        self,
        namespace: str | Mapping[str, Any],
        parameters: Iterable[Sequence[Any]] | None = None,
        ignore_override: bool = False,
    ) -> list[Parameter]:
        """rclpy's ``declare_parameters(namespace, [(name, value_or_type, descriptor), ...])``.

        aiorobot also takes a mapping ``{name: default}`` as the only argument.
        """
        if isinstance(namespace, Mapping):
            return self._parameters.declare_many("", list(namespace.items()))
        if parameters is None:
            raise TypeError("declare_parameters: expected (namespace, [(name, value, descriptor), ...])")
        return self._parameters.declare_many(namespace, parameters, ignore_override)

    def undeclare_parameter(self, name: str) -> None:
        """Remove a parameter; ``ParameterImmutableError`` when it is read-only."""
        self._parameters.undeclare(name)

    def has_parameter(self, name: str) -> bool:
        return self._parameters.has(name)

    def get_parameter(self, name: str) -> Parameter:
        return self._parameters.get(name)

    def get_parameters(self, names: Iterable[str]) -> list[Parameter]:
        names = list(names)
        if not all(isinstance(n, str) for n in names):
            raise TypeError(f"get_parameters: expected names as str, found {names!r}")
        return [self._parameters.get(n) for n in names]

    def get_parameter_or(self, name: str, alternative_value: Parameter | None = None) -> Parameter:
        """The parameter, or ``alternative_value`` (default: a NOT_SET parameter) when it is
        undeclared or has no value."""
        return self._parameters.get_or(name, alternative_value)

    def get_parameters_by_prefix(self, prefix: str) -> dict[str, Parameter]:
        """``{"kp": ..., "ki": ...}`` for ``pid.kp``, ``pid.ki`` and prefix ``"pid"``."""
        return self._parameters.by_prefix(prefix)

    def get_parameter_type(self, name: str) -> ParameterType:
        return self._parameters.type_of(name)

    def get_parameter_types(self, names: Iterable[str]) -> list[ParameterType]:
        return [self._parameters.type_of(n) for n in names]

    def describe_parameter(self, name: str) -> ParameterDescriptor:
        return self._parameters.describe(name)

    def describe_parameters(self, names: Iterable[str]) -> list[ParameterDescriptor]:
        return [self._parameters.describe(n) for n in names]

    def set_descriptor(self, name: str, descriptor: Any, alternative_value: Any = None) -> Any:
        """Replace a parameter's descriptor (rclpy's): a value that breaks the new descriptor is
        replaced by ``alternative_value`` (an ``rcl_interfaces`` ParameterValue) or raises
        ``InvalidParameterValueError``; a read-only parameter raises ``ParameterImmutableError``.
        Returns the parameter's value as a ParameterValue."""
        return self._parameters.set_descriptor(name, descriptor, alternative_value)

    def list_parameters(self, prefixes: Sequence[str] | None = None, depth: int = 0) -> Any:
        """rclpy's ``list_parameters(prefixes, depth)`` -> ``rcl_interfaces/msg/ListParametersResult``
        (``names``, ``prefixes``); ``depth`` 0 lists recursively.

        rclpy difference: both arguments are optional (no arguments lists every parameter).
        """
        from ..msgs.rcl_interfaces import ListParametersResult

        names, prefixes_found = self._parameters.list([] if prefixes is None else prefixes, depth)
        return ListParametersResult(names=names, prefixes=prefixes_found)

    def set_parameters(self, parameter_list: Iterable[Parameter]) -> list[SetParametersResult]:
        """Set each parameter on its own; one result per parameter saying whether and why not.

        An undeclared name raises ``ParameterNotDeclaredError`` (those before it are
        applied), unless the node allows undeclared parameters.
        """
        return self._parameters.set(parameter_list)

    async def set_parameters_async(self, parameter_list: Iterable[Parameter]) -> list[SetParametersResult]:
        """As :meth:`set_parameters`, awaiting ``async def`` callbacks."""
        return await self._parameters.set_async(parameter_list)

    def set_parameters_atomically(self, parameter_list: Iterable[Parameter]) -> SetParametersResult:
        """Set all or none: one result."""
        return self._parameters.set_atomically(parameter_list)

    async def set_parameters_atomically_async(self, parameter_list: Iterable[Parameter]) -> SetParametersResult:
        return await self._parameters.set_atomically_async(parameter_list)

    def add_pre_set_parameters_callback(self, callback: PreSetCallback) -> None:
        """``callback(params) -> params``: may change or extend what is about to be set."""
        self._parameters.add_pre_set_callback(callback)

    def add_on_set_parameters_callback(self, callback: OnSetCallback) -> OnSetCallback:
        """``callback(params) -> SetParametersResult`` vets every change (declarations too)."""
        self._parameters.add_on_set_callback(callback)
        return callback

    def add_post_set_parameters_callback(self, callback: PostSetCallback) -> None:
        """``callback(params)`` runs after a change is applied."""
        self._parameters.add_post_set_callback(callback)

    def remove_pre_set_parameters_callback(self, callback: PreSetCallback) -> None:
        self._parameters.remove_pre_set_callback(callback)

    def remove_on_set_parameters_callback(self, callback: OnSetCallback) -> None:
        self._parameters.remove_on_set_callback(callback)

    def remove_post_set_parameters_callback(self, callback: PostSetCallback) -> None:
        self._parameters.remove_post_set_callback(callback)

    def get_parameter_overrides(self) -> dict[str, Any]:
        """Every override given to the node as ``{name: value}``, whatever its source:
        ``parameter_overrides`` (code, a TOML table), ``-p`` and ``--params-file`` (rclcpp's
        ``get_parameter_overrides``). A node that reads its inputs from names it is given
        (robot_localization's ``odom0``, ``imu0``...) reads them here."""
        return dict(self._parameters.overrides)

    def get_parameter_override_source(self, name: str) -> str | None:
        """Where the override ``name`` was written (``"f.yaml: node.ros__parameters.x (line 3)"``,
        ``"--ros-args -p x"``), or ``None`` for code and TOML tables; for error messages."""
        return self._parameters.sources.get(name)

    def unclaimed_parameter_overrides(self) -> list[str]:
        """Overrides given to the node for parameters it never declared."""
        return self._parameters.unclaimed_overrides()
