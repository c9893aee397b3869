"""``LifecycleNode``: a node with ROS 2's managed states, transition hooks and lifecycle services."""

from __future__ import annotations

import asyncio
import inspect
from collections.abc import Callable
from typing import Any, TypeVar

from .._core._groups import ReentrantCallbackGroup
from .._core._node import Node
from .._core._qos import QoSProfile
from ._publisher import LifecyclePublisher
from ._state_machine import (
    STATES,
    TRANSITIONS,
    InvalidTransitionError,
    LifecycleState,
    LifecycleStateMachine,
    LifecycleTransition,
    TransitionCallbackReturn,
    TransitionDescription,
)

__all__ = ["LifecycleNode"]

M = TypeVar("M")

_HOOKS = {
    LifecycleState.CONFIGURING: "on_configure",
    LifecycleState.CLEANINGUP: "on_cleanup",
    LifecycleState.ACTIVATING: "on_activate",
    LifecycleState.DEACTIVATING: "on_deactivate",
    LifecycleState.SHUTTINGDOWN: "on_shutdown_transition",
    LifecycleState.ERRORPROCESSING: "on_error",
}


class LifecycleNode(Node):
    """A managed node (ROS 2 lifecycle): unconfigured -> inactive -> active, and back, to finalized.

    Override the async hooks ``on_configure``, ``on_activate``, ``on_deactivate``,
    ``on_cleanup``, ``on_shutdown_transition`` and ``on_error``; each receives the
    state the transition started from and returns a
    :class:`TransitionCallbackReturn` (``None`` means SUCCESS). FAILURE returns to
    the start state; ERROR, or an exception, goes to ``errorprocessing`` where
    ``on_error`` decides between ``unconfigured`` (SUCCESS) and ``finalized``.

    Drive it from code with ``await node.trigger_configure()`` etc. or
    ``await node.trigger_transition("activate")``, or from other nodes (and the
    ``ros2 lifecycle`` tools) through ``~/change_state``, ``~/get_state``,
    ``~/get_available_states``, ``~/get_available_transitions`` and
    ``~/get_transition_graph``; every step is published on ``~/transition_event``.

    ``on_shutdown`` (the runtime's shutdown hook) runs the shutdown transition
    when the node is not finalized yet; a subclass overriding it should await
    ``super().on_shutdown()``.

    Parameters
    ----------
    name, **kwargs
        As for :class:`~aiorobot.Node`.
    enable_communication_interface
        Create the lifecycle services and the transition event publisher.
    """

    def __init__(self, name: str, *, enable_communication_interface: bool = True, **kwargs: Any) -> None:
        if not isinstance(enable_communication_interface, bool):
            raise TypeError(
                f"enable_communication_interface: expected True or False, found {enable_communication_interface!r}"
            )
        super().__init__(name, **kwargs)
        self._machine = LifecycleStateMachine(self.get_fully_qualified_name())
        self._lifecycle_publishers: list[LifecyclePublisher[Any]] = []
        self._event_pub: Any = None
        self.lifecycle_services: list[Any] = []
        if enable_communication_interface:
            self._create_communication_interface()

    def __repr__(self) -> str:
        where = f" on {self.executor}" if self.executor else " (not added)"
        return f"<{type(self).__name__} {self.get_fully_qualified_name()} {self._machine.state.label}{where}>"

    # -- state ---------------------------------------------------------------------

    @property
    def current_state(self) -> LifecycleState:
        return self._machine.state

    def get_available_states(self) -> list[LifecycleState]:
        return list(STATES)

    def get_available_transitions(self) -> list[TransitionDescription]:
        """The transitions leaving the current state."""
        return self._machine.available_transitions()

    def get_transition_graph(self) -> list[TransitionDescription]:
        """Every transition of the state machine."""
        return list(TRANSITIONS)

    # -- hooks (override) ------------------------------------------------------------

    async def on_configure(self, state: LifecycleState) -> TransitionCallbackReturn | None:
        """unconfigured -> inactive: load parameters, create resources."""
        return TransitionCallbackReturn.SUCCESS

    async def on_activate(self, state: LifecycleState) -> TransitionCallbackReturn | None:
        """inactive -> active: start doing the work. Lifecycle publishers activate after it succeeds."""
        return TransitionCallbackReturn.SUCCESS

    async def on_deactivate(self, state: LifecycleState) -> TransitionCallbackReturn | None:
        """active -> inactive: stop the work. Lifecycle publishers are already deactivated."""
        return TransitionCallbackReturn.SUCCESS

    async def on_cleanup(self, state: LifecycleState) -> TransitionCallbackReturn | None:
        """inactive -> unconfigured: release what ``on_configure`` created."""
        return TransitionCallbackReturn.SUCCESS

    async def on_shutdown_transition(self, state: LifecycleState) -> TransitionCallbackReturn | None:
        """unconfigured, inactive or active -> finalized (the ROS ``on_shutdown`` transition hook)."""
        return TransitionCallbackReturn.SUCCESS

    async def on_error(self, state: LifecycleState) -> TransitionCallbackReturn | None:
        """After a hook returned ERROR or raised: SUCCESS recovers to unconfigured, else finalized."""
        return TransitionCallbackReturn.SUCCESS

    async def on_shutdown(self) -> None:
        """Runtime shutdown: take the shutdown transition unless finalized (as rclcpp on destruction).

        rclpy difference: rclpy's ``LifecycleNode.on_shutdown(state)`` is the shutdown
        *transition* hook; here that hook is ``on_shutdown_transition`` and
        ``on_shutdown`` is every node's runtime-shutdown hook (aiorobot's ``Node``
        contract), so a subclass overriding it must await ``super().on_shutdown()``.
        """
        state = self._machine.state
        if state.is_primary and state is not LifecycleState.FINALIZED:
            try:
                await self.trigger_shutdown()
            except InvalidTransitionError:
                pass

    # -- triggering ---------------------------------------------------------------------

    async def trigger_configure(self) -> LifecycleState:
        return await self.trigger_transition(LifecycleTransition.CONFIGURE)

    async def trigger_cleanup(self) -> LifecycleState:
        return await self.trigger_transition(LifecycleTransition.CLEANUP)

    async def trigger_activate(self) -> LifecycleState:
        return await self.trigger_transition(LifecycleTransition.ACTIVATE)

    async def trigger_deactivate(self) -> LifecycleState:
        return await self.trigger_transition(LifecycleTransition.DEACTIVATE)

    async def trigger_shutdown(self) -> LifecycleState:
        return await self.trigger_transition("shutdown")

    async def trigger_transition(self, transition: int | str | LifecycleTransition) -> LifecycleState:
        """Take ``transition`` (id, label or :class:`LifecycleTransition`) and return the state reached.

        Raises :class:`InvalidTransitionError`, naming the current state, when the
        current state does not offer the transition (also while another transition
        is in progress). A hook's FAILURE or ERROR is not an exception: the returned
        state tells where the node ended.
        """
        state, _ = await self.change_state(transition)
        return state

    async def change_state(
        self, transition: int | str | LifecycleTransition
    ) -> tuple[LifecycleState, TransitionCallbackReturn]:
        """As :meth:`trigger_transition`, also returning the hook's result (what ``~/change_state`` reports).

        The hooks run on the node's loop: called from another loop (a node on the
        priority loop driven from the main loop), the transition is handed over.
        """
        loop = self._loop
        if loop is not None and loop is not asyncio.get_running_loop():
            future = asyncio.run_coroutine_threadsafe(self._change_state(transition), loop)
            return await asyncio.wrap_future(future)
        return await self._change_state(transition)

    async def _change_state(
        self, transition: int | str | LifecycleTransition
    ) -> tuple[LifecycleState, TransitionCallbackReturn]:
        start = self._machine.state
        edge = self._machine.begin(transition)
        self._after_step(edge)
        result = await self._run_transition_hook(edge.goal_state, start)
        self._after_step(self._machine.finish(result))
        if result is TransitionCallbackReturn.ERROR:
            self.get_logger().warning(
                f"transition {edge.transition.label!r} from {start.label!r} ended in an error; running on_error"
            )
            error_result = await self._run_transition_hook(LifecycleState.ERRORPROCESSING, start)
            self._after_step(self._machine.finish(error_result))
        return self._machine.state, result

    async def _run_transition_hook(self, state: LifecycleState, previous: LifecycleState) -> TransitionCallbackReturn:
        name = _HOOKS[state]
        hook: Callable[[LifecycleState], Any] = getattr(self, name)
        try:
            result = hook(previous)
            if inspect.isawaitable(result):
                result = await result
        except asyncio.CancelledError:
            # Leave the transition state the way a failed hook would, then stop.
            self._after_step(self._machine.finish(TransitionCallbackReturn.FAILURE))
            raise
        except Exception:
            self.get_logger().error(f"{name} of {self.get_fully_qualified_name()} raised", exc_info=True)
            return TransitionCallbackReturn.ERROR
        if result is None:
            return TransitionCallbackReturn.SUCCESS
        if isinstance(result, TransitionCallbackReturn):
            return result
        self.get_logger().error(
            f"{name} of {self.get_fully_qualified_name()} returned {result!r}; expected a "
            f"TransitionCallbackReturn (SUCCESS, FAILURE, ERROR) or None. Treating it as ERROR"
        )
        return TransitionCallbackReturn.ERROR

    def _after_step(self, edge: TransitionDescription) -> None:
        """Sync the managed publishers with the new state and announce the step."""
        active = edge.goal_state is LifecycleState.ACTIVE
        for pub in self._lifecycle_publishers:
            if active:
                pub.on_activate()
            else:
                pub.on_deactivate()
        if self._event_pub is not None:
            from ..msgs.lifecycle_msgs import TransitionEvent

            self._event_pub.publish(
                TransitionEvent(
                    timestamp=self.now().nanoseconds,
                    transition=edge.transition.to_msg(),
                    start_state=edge.start_state.to_msg(),
                    goal_state=edge.goal_state.to_msg(),
                )
            )

    # -- managed entities ------------------------------------------------------------------

    def create_lifecycle_publisher(
        self, msg_type: type[M], topic: str, qos: QoSProfile | int
    ) -> LifecyclePublisher[M]:
        """A publisher that delivers only while this node is active."""
        pub = LifecyclePublisher(self, self.create_publisher(msg_type, topic, qos))
        if self._machine.state is LifecycleState.ACTIVE:
            pub.on_activate()
        self._lifecycle_publishers.append(pub)
        return pub

    def _destroy_lifecycle_publisher(self, pub: LifecyclePublisher[Any]) -> None:
        if pub in self._lifecycle_publishers:
            self._lifecycle_publishers.remove(pub)
            self.destroy_publisher(pub.publisher)

    # -- communication interface -------------------------------------------------------------

    def _create_communication_interface(self) -> None:
        from ..msgs.lifecycle_msgs import TransitionEvent

        self._event_pub = self.create_publisher(TransitionEvent, "~/transition_event", QoSProfile(depth=10))
        from ._services import create_lifecycle_services

        # Own reentrant group: get_state answers during a transition, and a hook that
        # awaits the node's own callbacks (default group) cannot deadlock the service.
        self.lifecycle_services = create_lifecycle_services(self, ReentrantCallbackGroup())
