"""``rclpy.parameter_client``: ``AsyncParameterClient`` over a remote node's parameter services.

As rclpy's: six clients of the ``rcl_interfaces`` services (``<node>/get_parameters``, ...)
on the given node; every request method returns the service call's ``Future`` (its result
is the service's ``Response``) and takes an optional done ``callback``. ``wait_for_services``
blocks the calling thread, polling, as rclpy's does.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from typing import Any

from ...msgs import rcl_interfaces as _ri
from ..._core._parameter_types import Parameter
from ..._core._parameter_files import parameter_dict_from_yaml_file
from .qos import qos_profile_parameter_events, qos_profile_services_default

__all__ = ["AsyncParameterClient"]

_SERVICES = (
    ("_get_parameter_client", _ri.GetParameters, "get_parameters"),
    ("_list_parameter_client", _ri.ListParameters, "list_parameters"),
    ("_set_parameter_client", _ri.SetParameters, "set_parameters"),
    ("_get_parameter_types_client", _ri.GetParameterTypes, "get_parameter_types"),
    ("_describe_parameters_client", _ri.DescribeParameters, "describe_parameters"),
    ("_set_parameters_atomically_client", _ri.SetParametersAtomically, "set_parameters_atomically"),
)


def _call(client: Any, request: Any, callback: Callable[[Any], None] | None) -> Any:
    future = client.call_async(request)
    if callback:
        future.add_done_callback(callback)
    return future


def _parameter_msgs(parameters: Sequence[Any]) -> list[Any]:
    return [p.to_parameter_msg() if isinstance(p, Parameter) else p for p in parameters]


class AsyncParameterClient:
    """Query and change the parameters of ``remote_node_name`` through its services."""

    def __init__(
        self, node: Any, remote_node_name: str, qos_profile: Any = qos_profile_services_default,
        callback_group: Any = None,
    ) -> None:
        self.remote_node_name = remote_node_name
        self.node = node
        for attr, srv_type, name in _SERVICES:
            setattr(self, attr, node.create_client(
                srv_type, f"{remote_node_name}/{name}", qos_profile=qos_profile, callback_group=callback_group
            ))

    def __repr__(self) -> str:
        return f"<AsyncParameterClient of {self.remote_node_name!r} on {self.node.get_name()!r}>"

    def services_are_ready(self) -> bool:
        return all(getattr(self, attr).service_is_ready() for attr, _t, _n in _SERVICES)

    def wait_for_services(self, timeout_sec: float | None = None) -> bool:
        """Block until all six services are available; ``False`` after ``timeout_sec``."""
        sleep_time = 0.25
        remaining = float("inf") if timeout_sec is None else timeout_sec
        while not self.services_are_ready() and remaining > 0.0:
            time.sleep(sleep_time)
            remaining -= sleep_time
        return self.services_are_ready()

    def list_parameters(
        self, prefixes: list[str] | None = None, depth: int | None = None,
        callback: Callable[[Any], None] | None = None,
    ) -> Any:
        request = _ri.ListParameters.Request()
        if prefixes:
            request.prefixes = prefixes
        if depth:
            request.depth = depth
        return _call(self._list_parameter_client, request, callback)  # type: ignore[attr-defined]

    def get_parameters(self, names: list[str], callback: Callable[[Any], None] | None = None) -> Any:
        request = _ri.GetParameters.Request(names=list(names))
        return _call(self._get_parameter_client, request, callback)  # type: ignore[attr-defined]

    def set_parameters(self, parameters: Sequence[Any], callback: Callable[[Any], None] | None = None) -> Any:
        request = _ri.SetParameters.Request(parameters=_parameter_msgs(parameters))
        return _call(self._set_parameter_client, request, callback)  # type: ignore[attr-defined]

    def describe_parameters(self, names: list[str], callback: Callable[[Any], None] | None = None) -> Any:
        request = _ri.DescribeParameters.Request(names=list(names))
        return _call(self._describe_parameters_client, request, callback)  # type: ignore[attr-defined]

    def get_parameter_types(self, names: list[str], callback: Callable[[Any], None] | None = None) -> Any:
        request = _ri.GetParameterTypes.Request(names=list(names))
        return _call(self._get_parameter_types_client, request, callback)  # type: ignore[attr-defined]

    def set_parameters_atomically(
        self, parameters: Sequence[Any], callback: Callable[[Any], None] | None = None
    ) -> Any:
        request = _ri.SetParametersAtomically.Request(parameters=_parameter_msgs(parameters))
        return _call(self._set_parameters_atomically_client, request, callback)  # type: ignore[attr-defined]

    def delete_parameters(self, names: list[str], callback: Callable[[Any], None] | None = None) -> Any:
        """Unset ``names`` (a NOT_SET value each): only dynamically typed parameters can be."""
        request = _ri.SetParameters.Request(parameters=[Parameter(name=n).to_parameter_msg() for n in names])
        return _call(self._set_parameter_client, request, callback)  # type: ignore[attr-defined]

    def load_parameter_file(
        self, parameter_file: str, use_wildcard: bool = False, callback: Callable[[Any], None] | None = None
    ) -> Any:
        param_dict = parameter_dict_from_yaml_file(parameter_file, use_wildcard)
        return self.set_parameters(list(param_dict.values()), callback=callback)

    def load_parameter_file_atomically(
        self, parameter_file: str, use_wildcard: bool = False, callback: Callable[[Any], None] | None = None
    ) -> Any:
        param_dict = parameter_dict_from_yaml_file(parameter_file, use_wildcard)
        return self.set_parameters_atomically(list(param_dict.values()), callback=callback)

    def on_parameter_event(
        self, callback: Callable[..., Any], qos_profile: Any = qos_profile_parameter_events, *,
        callback_group: Any = None, event_callbacks: Any = None, qos_overriding_options: Any = None,
        raw: bool = False,
    ) -> Any:
        return self.node.create_subscription(
            _ri.ParameterEvent, "/parameter_events", callback, qos_profile, callback_group=callback_group,
            event_callbacks=event_callbacks, qos_overriding_options=qos_overriding_options, raw=raw,
        )
