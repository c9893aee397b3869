"""The lifecycle services of a node (``~/change_state`` and friends, ``lifecycle_msgs`` types)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from ._state_machine import InvalidTransitionError, TransitionCallbackReturn

if TYPE_CHECKING:
    from .._core._groups import CallbackGroup
    from ._node import LifecycleNode

__all__ = ["create_lifecycle_services"]


def create_lifecycle_services(node: LifecycleNode, group: CallbackGroup) -> list[Any]:
    """Serve the five lifecycle services of ``node`` (names and behaviour as rclcpp_lifecycle)."""
    from ..msgs.lifecycle_msgs import ChangeState, GetAvailableStates, GetAvailableTransitions, GetState

    async def change_state(request: Any) -> Any:
        transition = request.transition
        # As rclcpp: a label takes precedence over the id (CLI requests leave the id at 0).
        key: int | str = transition.label if transition.label else int(transition.id)
        try:
            _, result = await node.change_state(key)
        except InvalidTransitionError as exc:
            node.get_logger().warning(f"~/change_state refused: {exc}")
            return ChangeState.Response(success=False)
        return ChangeState.Response(success=result is TransitionCallbackReturn.SUCCESS)

    def get_state(_request: Any) -> Any:
        return GetState.Response(current_state=node.current_state.to_msg())

    def get_available_states(_request: Any) -> Any:
        return GetAvailableStates.Response(available_states=[s.to_msg() for s in node.get_available_states()])

    def get_available_transitions(_request: Any) -> Any:
        return GetAvailableTransitions.Response(
            available_transitions=[t.to_msg() for t in node.get_available_transitions()]
        )

    def get_transition_graph(_request: Any) -> Any:
        return GetAvailableTransitions.Response(
            available_transitions=[t.to_msg() for t in node.get_transition_graph()]
        )

    return [
        node.create_service(ChangeState, "~/change_state", change_state, callback_group=group),
        node.create_service(GetState, "~/get_state", get_state, callback_group=group),
        node.create_service(GetAvailableStates, "~/get_available_states", get_available_states, callback_group=group),
        node.create_service(
            GetAvailableTransitions, "~/get_available_transitions", get_available_transitions, callback_group=group
        ),
        node.create_service(
            GetAvailableTransitions, "~/get_transition_graph", get_transition_graph, callback_group=group
        ),
    ]
