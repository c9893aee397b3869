"""The parameter methods of ``Node``, composed over a :class:`ParameterStore`."""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import Any

from ._parameters import (
    OnSetCallback,
    Parameter,
    ParameterDescriptor,
    ParameterStore,
    SetParametersResult,
)

__all__ = ["NodeParametersMixin"]


class NodeParametersMixin:
    """rclpy's parameter methods; the node owns one :class:`ParameterStore` as ``_parameters``."""

    _parameters: ParameterStore

    def declare_parameter(
        self,
        name: str,
        default: Any = None,
        *,
        description: str = "",
        read_only: bool = False,
        range: Iterable[float] | None = None,
    ) -> Parameter:
        """Declare a parameter; an override given to the node replaces ``default``.

        Raises ``InvalidParameterValueError`` when the override has the wrong type
        or lies outside ``range`` (``(from, to)`` or ``(from, to, step)``).
        """
        return self._parameters.declare(
            name,
            default,
            description=description,
            read_only=read_only,
            range=tuple(range) if range is not None else None,
        )

    def declare_parameters(self, values: Mapping[str, Any]) -> list[Parameter]:
        return [self.declare_parameter(name, value) for name, value in values.items()]

    def has_parameter(self, name: str) -> bool:
        return self._parameters.has(name)

    def get_parameter(self, name: str) -> Parameter:
        return self._parameters.get(name)

    def get_parameters(self, names: Iterable[str]) -> list[Parameter]:
        return [self._parameters.get(n) for n in names]

    def describe_parameter(self, name: str) -> ParameterDescriptor:
        return self._parameters.describe(name)

    def list_parameters(self) -> list[str]:
        return self._parameters.names()

    def set_parameters(self, parameters: Iterable[Parameter]) -> list[SetParametersResult]:
        """Set each parameter; one result per parameter saying whether and why not."""
        return self._parameters.set(parameters)

    async def set_parameters_async(self, parameters: Iterable[Parameter]) -> list[SetParametersResult]:
        """As :meth:`set_parameters`, awaiting ``async def`` on-set callbacks."""
        return await self._parameters.set_async(parameters)

    def add_on_set_parameters_callback(self, callback: OnSetCallback) -> OnSetCallback:
        """``callback(params) -> SetParametersResult`` vets every change before it applies."""
        return self._parameters.add_callback(callback)

    def remove_on_set_parameters_callback(self, callback: OnSetCallback) -> None:
        self._parameters.remove_callback(callback)

    def unclaimed_parameter_overrides(self) -> list[str]:
        """Overrides given to the node for parameters it never declared."""
        return self._parameters.unclaimed_overrides()
