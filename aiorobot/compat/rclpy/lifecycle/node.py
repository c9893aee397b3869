"""``rclpy.lifecycle.node``: rclpy's ``LifecycleNode`` (synchronous transitions) on aiorobot's.

The states, transitions, services and transition events are aiorobot.lifecycle's
(rcl_lifecycle's state machine); this module gives them rclpy's face: transition
callbacks are plain methods taking a :class:`LifecycleState` and returning a
``TransitionCallbackReturn``, ``trigger_*()`` run a transition at once in the
calling thread and return the callback's result, and the default callbacks drive
the node's managed entities (its lifecycle publishers), as in rclpy.
"""

from __future__ import annotations

import inspect
from collections.abc import Callable
from typing import Any, NamedTuple, TypeVar

from ....lifecycle import InvalidTransitionError, TransitionCallbackReturn
from ....lifecycle import LifecycleNode as _AioLifecycleNode
from ....lifecycle import LifecycleState as _AioState
from ....lifecycle import LifecycleTransition as _Transition
from ....lifecycle._state_machine import STATES, TRANSITIONS
from ..._node import make_node_class
from .managed_entity import ManagedEntity
from .publisher import LifecyclePublisher

__all__ = ["LifecycleNode", "LifecycleNodeMixin", "LifecycleState", "TransitionCallbackReturn"]

MsgT = TypeVar("MsgT")

_CALLBACK_NAMES = ("on_configure", "on_cleanup", "on_shutdown", "on_activate", "on_deactivate", "on_error")
#: the transition state whose callback each name is (rclpy registers them in this order)
_CALLBACK_STATES = (
    _AioState.CONFIGURING, _AioState.CLEANINGUP, _AioState.SHUTTINGDOWN, _AioState.ACTIVATING,
    _AioState.DEACTIVATING, _AioState.ERRORPROCESSING,
)
_SERVICE_NAMES = (
    "change_state", "get_state", "get_available_states", "get_available_transitions", "get_transition_graph",
)
_SHUTDOWN_FROM = {
    _AioState.UNCONFIGURED: _Transition.UNCONFIGURED_SHUTDOWN,
    _AioState.INACTIVE: _Transition.INACTIVE_SHUTDOWN,
    _AioState.ACTIVE: _Transition.ACTIVE_SHUTDOWN,
}


class LifecycleState(NamedTuple):
    """A state as rclpy hands it to transition callbacks: ``State(label='unconfigured', state_id=1)``."""

    label: str
    state_id: int


def _rclpy_state(state: _AioState) -> LifecycleState:
    return LifecycleState(label=state.label, state_id=int(state))


def _edge_tuple(edge: Any) -> tuple[int, str, int, str, int, str]:
    return (
        int(edge.transition), edge.transition.label, int(edge.start_state), edge.start_state.label,
        int(edge.goal_state), edge.goal_state.label,
    )


class _StateMachineView:
    """rclpy's ``node._state_machine``, as far as programs and rclpy's own tests read it."""

    initialized = True

    def __init__(self, node: _AioLifecycleNode, services: dict[str, Any]) -> None:
        self._node = node
        self.service_change_state = services.get("change_state")
        self.service_get_state = services.get("get_state")
        self.service_get_available_states = services.get("get_available_states")
        self.service_get_available_transitions = services.get("get_available_transitions")
        self.service_get_transition_graph = services.get("get_transition_graph")

    def __repr__(self) -> str:
        return f"<LifecycleStateMachine {self._node.get_fully_qualified_name()} {self.current_state[1]}>"

    @property
    def current_state(self) -> tuple[int, str]:
        state = self._node.current_state
        return int(state), state.label

    @property
    def available_states(self) -> list[tuple[int, str]]:
        return [(int(s), s.label) for s in STATES]

    @property
    def available_transitions(self) -> list[tuple[int, str, int, str, int, str]]:
        return [_edge_tuple(t) for t in self._node.get_available_transitions()]

    @property
    def transition_graph(self) -> list[tuple[int, str, int, str, int, str]]:
        return [_edge_tuple(t) for t in TRANSITIONS]


class LifecycleNodeMixin(ManagedEntity):
    """rclpy's lifecycle API over an aiorobot ``LifecycleNode``; the first base of :class:`LifecycleNode`.

    Differs from rclpy (see docs/rclpy-compat.md): rclpy's mixin can be combined with any ``rclpy.node.Node``;
    aiorobot's needs aiorobot's lifecycle machinery, so use it only through
    :class:`LifecycleNode` (``class MyNode(LifecycleNode)``).
    """

    _machine: Any

    def __init__(self, *, enable_communication_interface: bool = True, callback_group: Any = None) -> None:
        if not isinstance(self, _AioLifecycleNode):
            raise RuntimeError(
                f"LifecycleNodeMixin: {type(self).__name__} combines it with a plain Node; on aiorobot the "
                "lifecycle API needs aiorobot's LifecycleNode underneath: derive from "
                "rclpy.lifecycle.LifecycleNode instead"
            )
        self._callbacks: dict[int, Callable[[LifecycleState], TransitionCallbackReturn]] = {}
        for state, name in zip(_CALLBACK_STATES, _CALLBACK_NAMES):
            self.__register_callback(int(state), getattr(self, name))
        self._managed_entities: set[ManagedEntity] = set()
        services = dict(zip(_SERVICE_NAMES, self.lifecycle_services))  # type: ignore[attr-defined]
        for name, service in services.items():
            setattr(self, f"_service_{name}", service)
        self._state_machine = _StateMachineView(self, services)  # type: ignore[arg-type]

    # -- triggering (synchronous, in the calling thread, as rclpy) ----------------------------

    def trigger_configure(self) -> TransitionCallbackReturn:
        return self.__change_state(_Transition.CONFIGURE)

    def trigger_cleanup(self) -> TransitionCallbackReturn:
        return self.__change_state(_Transition.CLEANUP)

    def trigger_shutdown(self) -> TransitionCallbackReturn:
        state = self._machine.state
        if state in _SHUTDOWN_FROM:
            return self.__change_state(_SHUTDOWN_FROM[state])
        raise RuntimeError(
            f"Shutdown transtion not possible: {self.get_fully_qualified_name()} is "  # type: ignore[attr-defined]
            f"{state.label!r}; shutdown is possible from 'unconfigured', 'inactive' or 'active'"
        )

    def trigger_activate(self) -> TransitionCallbackReturn:
        return self.__change_state(_Transition.ACTIVATE)

    def trigger_deactivate(self) -> TransitionCallbackReturn:
        return self.__change_state(_Transition.DEACTIVATE)

    # -- managed entities -------------------------------------------------------------------

    def add_managed_entity(self, entity: ManagedEntity) -> None:
        if not isinstance(entity, ManagedEntity):
            raise TypeError("Expected a rclpy.lifecycle.ManagedEntity instance.")
        self._managed_entities.add(entity)

    def __transition_callback_impl(self, callback_name: str, state: LifecycleState) -> TransitionCallbackReturn:
        for entity in list(self._managed_entities):
            ret = getattr(entity, callback_name)(state)
            if not isinstance(ret, TransitionCallbackReturn):
                raise TypeError(
                    f"{callback_name}() return value of class {type(entity)} should be `TransitionCallbackReturn`.\n"
                    f"Instance of the class that caused the failure: {entity}"
                )
            if ret != TransitionCallbackReturn.SUCCESS:
                return ret
        return TransitionCallbackReturn.SUCCESS

    # -- the default transition callbacks: drive the managed entities ---------------------------

    def on_configure(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Default: every managed entity's ``on_configure``, stopping at the first not SUCCESS."""
        return self.__transition_callback_impl("on_configure", state)

    def on_cleanup(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Default: every managed entity's ``on_cleanup``, stopping at the first not SUCCESS."""
        return self.__transition_callback_impl("on_cleanup", state)

    def on_shutdown(self, state: LifecycleState) -> TransitionCallbackReturn:  # type: ignore[override]
        """Default: every managed entity's ``on_shutdown``, stopping at the first not SUCCESS.

        This is rclpy's shutdown *transition* callback; the runtime-shutdown hook that
        aiorobot's ``Node.on_shutdown()`` is elsewhere does nothing for these nodes,
        as rclpy takes no transition when the context shuts down.
        """
        return self.__transition_callback_impl("on_shutdown", state)

    def on_activate(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Default: activates the lifecycle publishers (every managed entity's ``on_activate``)."""
        return self.__transition_callback_impl("on_activate", state)

    def on_deactivate(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Default: deactivates the lifecycle publishers (every managed entity's ``on_deactivate``)."""
        return self.__transition_callback_impl("on_deactivate", state)

    def on_error(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Default: every managed entity's ``on_error``; SUCCESS recovers to unconfigured."""
        return self.__transition_callback_impl("on_error", state)

    # -- lifecycle publishers ----------------------------------------------------------------

    def create_lifecycle_publisher(
        self, msg_type: type[MsgT], topic: str, qos_profile: Any, *, publisher_class: None = None, **kwargs: Any
    ) -> LifecyclePublisher[MsgT]:
        """A publisher that publishes only while activated; a managed entity of this node."""
        if publisher_class:
            raise TypeError("create_publisher() got an unexpected keyword argument 'publisher_class'")
        pub: LifecyclePublisher[MsgT] = LifecyclePublisher(
            self.create_publisher(msg_type, topic, qos_profile, **kwargs)  # type: ignore[attr-defined]
        )
        self._managed_entities.add(pub)
        return pub

    def destroy_lifecycle_publisher(self, publisher: LifecyclePublisher[Any]) -> bool:
        self._managed_entities.discard(publisher)
        return self.destroy_publisher(publisher)

    def destroy_publisher(self, publisher: Any) -> bool:
        """Also takes a :class:`LifecyclePublisher` (as rclpy), which stops being managed."""
        if isinstance(publisher, LifecyclePublisher):
            self._managed_entities.discard(publisher)
            publisher = publisher.publisher
        return bool(super().destroy_publisher(publisher))  # type: ignore[misc]

    # -- the transition itself ------------------------------------------------------------------

    def __register_callback(
        self, state_id: int, callback: Callable[[LifecycleState], TransitionCallbackReturn]
    ) -> bool:
        """The callback run on entering ``state_id``; it gets the state the transition started from."""
        self._callbacks[state_id] = callback
        return True

    def __execute_callback(self, current: _AioState, previous: LifecycleState) -> TransitionCallbackReturn:
        callback = self._callbacks.get(int(current))
        if callback is None:
            return TransitionCallbackReturn.SUCCESS
        name = getattr(callback, "__name__", repr(callback))
        node = self.get_fully_qualified_name()  # type: ignore[attr-defined]
        try:
            ret = callback(previous)
        except Exception:
            self.get_logger().error(  # type: ignore[attr-defined]
                f"{name}() of {node} raised; the transition ends in ERROR", exc_info=True
            )
            return TransitionCallbackReturn.ERROR
        if isinstance(ret, TransitionCallbackReturn):
            return ret
        hint = ""
        if inspect.iscoroutine(ret):
            ret.close()
            hint = " (rclpy.lifecycle callbacks are plain functions: drop 'async')"
        self.get_logger().error(  # type: ignore[attr-defined]
            f"{name}() of {node} returned {ret!r}; expected TransitionCallbackReturn.SUCCESS, FAILURE or "
            f"ERROR{hint}. Treating it as ERROR"
        )
        return TransitionCallbackReturn.ERROR

    def __change_state(self, transition: int | str) -> TransitionCallbackReturn:
        """Take ``transition``, run its callback (and on_error on ERROR); the callback's result.

        A transition the current state does not offer is logged and returns ERROR (rclpy).
        """
        machine = self._machine
        start = machine.state
        try:
            edge = machine.begin(transition)
        except InvalidTransitionError as err:
            shown = transition if isinstance(transition, str) else int(transition)
            self.get_logger().error(  # type: ignore[attr-defined]
                f"Unable to start transition {shown} from current state {(int(start), start.label)}: {err}"
            )
            return TransitionCallbackReturn.ERROR
        after_step = self._after_step  # type: ignore[attr-defined]
        after_step(edge)
        previous = _rclpy_state(start)
        result = self.__execute_callback(machine.state, previous)
        after_step(machine.finish(result))
        if result is TransitionCallbackReturn.ERROR:
            after_step(machine.finish(self.__execute_callback(machine.state, previous)))
        return result

    async def _change_state(self, transition: int | str) -> tuple[_AioState, TransitionCallbackReturn]:
        """What the ``~/change_state`` service runs: the same synchronous transition."""
        result = self.__change_state(transition)
        return self._machine.state, result

    async def _run_hook(self, hook: Callable[[], Any], what: str) -> BaseException | None:
        if what == "on_shutdown":
            return None  # rclpy's on_shutdown(state) is the transition callback, not a runtime hook
        return await super()._run_hook(hook, what)  # type: ignore[misc, no-any-return]


_LifecycleNodeBase: Any = make_node_class(
    _AioLifecycleNode, "LifecycleNode", __name__, "rclpy's constructor over aiorobot's LifecycleNode."
)


class LifecycleNode(LifecycleNodeMixin, _LifecycleNodeBase):  # type: ignore[misc]
    """rclpy's managed node on aiorobot's ``LifecycleNode``.

    Construct it as rclpy's (``LifecycleNode('talker', enable_communication_interface=True,
    namespace=..., ...)``); override ``on_configure`` / ``on_cleanup`` / ``on_activate`` /
    ``on_deactivate`` / ``on_shutdown`` / ``on_error`` as plain methods taking the previous
    :class:`LifecycleState` and returning a ``TransitionCallbackReturn``. The lifecycle
    services (``~/change_state``, ``~/get_state``, ...) run transitions when an executor
    spins; ``trigger_configure()`` and friends run them at once.
    """

    def __init__(self, node_name: str, *, enable_communication_interface: bool = True, **kwargs: Any) -> None:
        _LifecycleNodeBase.__init__(
            self, node_name, enable_communication_interface=enable_communication_interface, **kwargs
        )
        LifecycleNodeMixin.__init__(self, enable_communication_interface=enable_communication_interface)
