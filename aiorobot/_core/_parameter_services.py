"""A node's parameter services (``~/get_parameters`` and the rest) and its ``/parameter_events``.

They are ordinary services and an ordinary topic with ``rcl_interfaces`` types, answered
as rclpy's ``ParameterService`` answers, so ``ros2 param`` and ``aiorobot param`` reach
a node through any transport.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from ._errors import ParameterNotDeclaredError, ParameterUninitializedError
from ._parameter_types import Parameter, SetParametersResult
from ._qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

if TYPE_CHECKING:
    from ._node import Node

__all__ = ["SERVICE_NAMES", "ParameterEventPublisher", "create_parameter_services", "qos_profile_parameter_events"]

#: rclpy's ``qos_profile_parameter_events``
qos_profile_parameter_events = QoSProfile(
    reliability=ReliabilityPolicy.RELIABLE,
    durability=DurabilityPolicy.VOLATILE,
    history=HistoryPolicy.KEEP_LAST,
    depth=1000,
)

#: the services every node offers under its own name, with their types
SERVICE_NAMES = (
    ("describe_parameters", "DescribeParameters"),
    ("get_parameters", "GetParameters"),
    ("get_parameter_types", "GetParameterTypes"),
    ("list_parameters", "ListParameters"),
    ("set_parameters", "SetParameters"),
    ("set_parameters_atomically", "SetParametersAtomically"),
)


class ParameterEventPublisher:
    """Publishes a ``rcl_interfaces/msg/ParameterEvent`` for every declare, set and undeclare."""

    def __init__(self, node: Node) -> None:
        from ..msgs.rcl_interfaces import ParameterEvent

        self._node = node
        self._event_type = ParameterEvent
        self.publisher = node.create_publisher(ParameterEvent, "/parameter_events", qos_profile_parameter_events)

    def __call__(self, new: list[Parameter], changed: list[Parameter], deleted: list[Parameter]) -> None:
        node = self._node
        if node._runtime is None or self.publisher.destroyed:  # nobody can be listening yet
            return
        self.publisher.publish(
            self._event_type(
                stamp=node.get_clock().now().to_msg(),
                node=node.get_fully_qualified_name(),
                new_parameters=[p.to_parameter_msg() for p in new],
                changed_parameters=[p.to_parameter_msg() for p in changed],
                deleted_parameters=[p.to_parameter_msg() for p in deleted],
            )
        )


def create_parameter_services(node: Node) -> list[Any]:
    """Create the six parameter services of ``node`` (rclpy's ``ParameterService``)."""
    from ..msgs import rcl_interfaces as ri

    handlers = _Handlers(node)
    return [
        node.create_service(getattr(ri, type_name), f"{node.get_name()}/{name}", getattr(handlers, name))
        for name, type_name in SERVICE_NAMES
    ]


class _Handlers:
    """rclpy's answers: an unknown name empties the whole answer; sets never raise."""

    def __init__(self, node: Node) -> None:
        from ..msgs import rcl_interfaces as ri

        self.node = node
        self.ri = ri

    def describe_parameters(self, request: Any) -> Any:
        response = self.ri.DescribeParameters.Response()
        try:
            response.descriptors = [self.node.describe_parameter(n).to_msg() for n in request.names]
        except ParameterNotDeclaredError:
            pass
        return response

    def get_parameters(self, request: Any) -> Any:
        response = self.ri.GetParameters.Response()
        try:
            response.values = [self.node.get_parameter(n).get_parameter_value() for n in request.names]
        except (ParameterNotDeclaredError, ParameterUninitializedError):
            pass
        return response

    def get_parameter_types(self, request: Any) -> Any:
        try:
            types = [int(self.node.get_parameter_type(n)) for n in request.names]
        except ParameterNotDeclaredError:
            types = []
        return self.ri.GetParameterTypes.Response(types=types)

    def list_parameters(self, request: Any) -> Any:
        response = self.ri.ListParameters.Response()
        try:
            response.result = self.node.list_parameters(list(request.prefixes), int(request.depth))
        except (TypeError, ValueError):
            pass
        return response

    async def set_parameters(self, request: Any) -> Any:
        results = []
        for msg in request.parameters:
            results.append(_result_msg(self.ri, await self._set_atomically([msg])))
        return self.ri.SetParameters.Response(results=results)

    async def set_parameters_atomically(self, request: Any) -> Any:
        result = await self._set_atomically(list(request.parameters))
        return self.ri.SetParametersAtomically.Response(result=_result_msg(self.ri, result))

    async def _set_atomically(self, msgs: list[Any]) -> SetParametersResult:
        try:
            params = [Parameter.from_parameter_msg(m) for m in msgs]
        except (TypeError, ValueError, RuntimeError) as err:
            return SetParametersResult(False, str(err))
        try:
            return await self.node.set_parameters_atomically_async(params)
        except ParameterNotDeclaredError as err:
            return SetParametersResult(False, str(err))


def _result_msg(ri: Any, result: SetParametersResult) -> Any:
    return ri.SetParametersResult(successful=result.successful, reason=result.reason)
