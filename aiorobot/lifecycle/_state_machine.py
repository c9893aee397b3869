"""ROS 2's managed-node state machine, pure: states, transitions, and the rules between them.

The states, transitions, ids and labels are those of ``rcl_lifecycle``'s default
state machine (design.ros2.org/articles/node_lifecycle.html), so they match
``lifecycle_msgs`` and the ``ros2 lifecycle`` tools. A user-visible transition
(configure, cleanup, activate, deactivate, shutdown) moves a primary state to a
transition state; the hook's result (:class:`TransitionCallbackReturn`) then
moves it on: SUCCESS to the goal, FAILURE back, ERROR to ``errorprocessing``,
whose hook's result gives ``unconfigured`` (SUCCESS) or ``finalized``.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass
from typing import Any

__all__ = [
    "InvalidTransitionError",
    "LifecycleState",
    "LifecycleStateMachine",
    "LifecycleTransition",
    "TransitionCallbackReturn",
    "TransitionDescription",
    "TRANSITIONS",
]


class LifecycleState(enum.IntEnum):
    """The states of a managed node; values are the ``lifecycle_msgs/msg/State`` ids."""

    UNKNOWN = 0
    UNCONFIGURED = 1
    INACTIVE = 2
    ACTIVE = 3
    FINALIZED = 4
    CONFIGURING = 10
    CLEANINGUP = 11
    SHUTTINGDOWN = 12
    ACTIVATING = 13
    DEACTIVATING = 14
    ERRORPROCESSING = 15

    @property
    def label(self) -> str:
        """The ROS label (``"unconfigured"``, ``"activating"``, ...)."""
        return self.name.lower()

    @property
    def is_primary(self) -> bool:
        """Whether this is a primary (resting) state rather than a transition state."""
        return self.value < 10

    def to_msg(self) -> Any:
        from ..msgs.lifecycle_msgs import State

        return State(id=int(self), label=self.label)

    def __str__(self) -> str:
        return self.label


class LifecycleTransition(enum.IntEnum):
    """The transitions; values are the ``lifecycle_msgs/msg/Transition`` ids."""

    CONFIGURE = 1
    CLEANUP = 2
    ACTIVATE = 3
    DEACTIVATE = 4
    UNCONFIGURED_SHUTDOWN = 5
    INACTIVE_SHUTDOWN = 6
    ACTIVE_SHUTDOWN = 7
    ON_CONFIGURE_SUCCESS = 10
    ON_CONFIGURE_FAILURE = 11
    ON_CONFIGURE_ERROR = 12
    ON_CLEANUP_SUCCESS = 20
    ON_CLEANUP_FAILURE = 21
    ON_CLEANUP_ERROR = 22
    ON_ACTIVATE_SUCCESS = 30
    ON_ACTIVATE_FAILURE = 31
    ON_ACTIVATE_ERROR = 32
    ON_DEACTIVATE_SUCCESS = 40
    ON_DEACTIVATE_FAILURE = 41
    ON_DEACTIVATE_ERROR = 42
    ON_SHUTDOWN_SUCCESS = 50
    ON_SHUTDOWN_FAILURE = 51
    ON_SHUTDOWN_ERROR = 52
    ON_ERROR_SUCCESS = 60
    ON_ERROR_FAILURE = 61
    ON_ERROR_ERROR = 62

    @property
    def label(self) -> str:
        """The rcl label: ``"configure"``, ``"shutdown"``, ``"transition_success"``, ..."""
        if self.value >= 10:
            return ("transition_success", "transition_failure", "transition_error")[self.value % 10]
        if self.name.endswith("SHUTDOWN"):
            return "shutdown"
        return self.name.lower()

    def to_msg(self) -> Any:
        from ..msgs.lifecycle_msgs import Transition

        return Transition(id=int(self), label=self.label)

    def __str__(self) -> str:
        return self.label


class TransitionCallbackReturn(enum.IntEnum):
    """What a transition hook returns (``None`` counts as SUCCESS); values as ``lifecycle_msgs``."""

    SUCCESS = 97
    FAILURE = 98
    ERROR = 99

    def to_label(self) -> str:
        """The label of the transition this result takes (rclpy's ``to_label``): ``"transition_success"``, ..."""
        return f"transition_{self.name.lower()}"


@dataclass(frozen=True)
class TransitionDescription:
    """One edge of the state machine."""

    transition: LifecycleTransition
    start_state: LifecycleState
    goal_state: LifecycleState

    def __str__(self) -> str:
        return f"{self.transition.label} [{int(self.transition)}]: {self.start_state.label} -> {self.goal_state.label}"

    def to_msg(self) -> Any:
        from ..msgs.lifecycle_msgs import TransitionDescription as Msg

        return Msg(
            transition=self.transition.to_msg(),
            start_state=self.start_state.to_msg(),
            goal_state=self.goal_state.to_msg(),
        )


def _t(transition: LifecycleTransition, start: LifecycleState, goal: LifecycleState) -> TransitionDescription:
    return TransitionDescription(transition, start, goal)


_S = LifecycleState
_T = LifecycleTransition

#: Every edge of rcl_lifecycle's default state machine, in its registration order.
TRANSITIONS: tuple[TransitionDescription, ...] = (
    _t(_T.CONFIGURE, _S.UNCONFIGURED, _S.CONFIGURING),
    _t(_T.ON_CONFIGURE_SUCCESS, _S.CONFIGURING, _S.INACTIVE),
    _t(_T.ON_CONFIGURE_FAILURE, _S.CONFIGURING, _S.UNCONFIGURED),
    _t(_T.ON_CONFIGURE_ERROR, _S.CONFIGURING, _S.ERRORPROCESSING),
    _t(_T.CLEANUP, _S.INACTIVE, _S.CLEANINGUP),
    _t(_T.ON_CLEANUP_SUCCESS, _S.CLEANINGUP, _S.UNCONFIGURED),
    _t(_T.ON_CLEANUP_FAILURE, _S.CLEANINGUP, _S.INACTIVE),
    _t(_T.ON_CLEANUP_ERROR, _S.CLEANINGUP, _S.ERRORPROCESSING),
    _t(_T.ACTIVATE, _S.INACTIVE, _S.ACTIVATING),
    _t(_T.ON_ACTIVATE_SUCCESS, _S.ACTIVATING, _S.ACTIVE),
    _t(_T.ON_ACTIVATE_FAILURE, _S.ACTIVATING, _S.INACTIVE),
    _t(_T.ON_ACTIVATE_ERROR, _S.ACTIVATING, _S.ERRORPROCESSING),
    _t(_T.DEACTIVATE, _S.ACTIVE, _S.DEACTIVATING),
    _t(_T.ON_DEACTIVATE_SUCCESS, _S.DEACTIVATING, _S.INACTIVE),
    _t(_T.ON_DEACTIVATE_FAILURE, _S.DEACTIVATING, _S.ACTIVE),
    _t(_T.ON_DEACTIVATE_ERROR, _S.DEACTIVATING, _S.ERRORPROCESSING),
    _t(_T.UNCONFIGURED_SHUTDOWN, _S.UNCONFIGURED, _S.SHUTTINGDOWN),
    _t(_T.INACTIVE_SHUTDOWN, _S.INACTIVE, _S.SHUTTINGDOWN),
    _t(_T.ACTIVE_SHUTDOWN, _S.ACTIVE, _S.SHUTTINGDOWN),
    _t(_T.ON_SHUTDOWN_SUCCESS, _S.SHUTTINGDOWN, _S.FINALIZED),
    _t(_T.ON_SHUTDOWN_FAILURE, _S.SHUTTINGDOWN, _S.FINALIZED),
    _t(_T.ON_SHUTDOWN_ERROR, _S.SHUTTINGDOWN, _S.ERRORPROCESSING),
    _t(_T.ON_ERROR_SUCCESS, _S.ERRORPROCESSING, _S.UNCONFIGURED),
    _t(_T.ON_ERROR_FAILURE, _S.ERRORPROCESSING, _S.FINALIZED),
    _t(_T.ON_ERROR_ERROR, _S.ERRORPROCESSING, _S.FINALIZED),
)

#: The primary states, then the transition states (as ``get_available_states`` lists them).
STATES: tuple[LifecycleState, ...] = tuple(s for s in LifecycleState)

_RESULT_OFFSET = {
    TransitionCallbackReturn.SUCCESS: 0,
    TransitionCallbackReturn.FAILURE: 1,
    TransitionCallbackReturn.ERROR: 2,
}


class InvalidTransitionError(RuntimeError):
    """A transition was requested that the current state does not offer."""


class LifecycleStateMachine:
    """The current state and the two-step transitions of a managed node.

    ``begin(transition)`` leaves a primary state for a transition state;
    ``finish(result)`` takes the hook's result and leaves the transition state.
    Both return the edge taken. ``owner`` names the node in error messages.
    """

    def __init__(self, owner: str = "lifecycle node") -> None:
        self.owner = owner
        self.state = LifecycleState.UNCONFIGURED

    def __repr__(self) -> str:
        return f"<LifecycleStateMachine {self.owner} {self.state.label}>"

    def available_transitions(self) -> list[TransitionDescription]:
        """The edges leaving the current state (for a transition state: its three results)."""
        return [t for t in TRANSITIONS if t.start_state is self.state]

    def resolve(self, transition: int | str | LifecycleTransition) -> TransitionDescription:
        """The user-visible edge from the current state given by id or label; raises if there is none.

        ``"shutdown"`` (label) picks the shutdown transition of the current state;
        so does the id of any of the three shutdown transitions.
        """
        if isinstance(transition, str):
            label = transition
            matches = [t for t in self.available_transitions() if t.transition.label == label and t.transition < 10]
            known = label in {t.transition.label for t in TRANSITIONS if t.transition < 10}
            if not known:
                raise InvalidTransitionError(
                    f"{self.owner}: unknown transition {label!r}; expected one of "
                    f"'configure', 'cleanup', 'activate', 'deactivate', 'shutdown' or a transition id"
                )
        else:
            if isinstance(transition, bool) or not isinstance(transition, int):
                raise TypeError(f"transition: expected an id (int) or a label (str), got {transition!r}")
            try:
                wanted = LifecycleTransition(transition)
            except ValueError:
                raise InvalidTransitionError(
                    f"{self.owner}: unknown transition id {transition!r}; expected one of "
                    f"{', '.join(str(int(t)) for t in LifecycleTransition if t < 10)}"
                ) from None
            label = wanted.label
            if label == "shutdown":
                matches = [t for t in self.available_transitions() if t.transition.label == "shutdown"]
            else:
                matches = [t for t in self.available_transitions() if t.transition is wanted]
            if wanted >= 10:
                raise InvalidTransitionError(
                    f"{self.owner}: transition {label!r} [{int(wanted)}] follows a hook's result and cannot be "
                    f"requested; request one of {self._offer()}"
                )
        if not matches:
            raise InvalidTransitionError(
                f"{self.owner}: cannot {label!r} from state {self.state.label!r}; "
                f"valid from {self.state.label!r}: {self._offer()}"
            )
        return matches[0]

    def _offer(self) -> str:
        offer = [t.transition.label for t in self.available_transitions() if t.transition < 10]
        if not offer:
            return "none (it is a transition state; wait for it to finish)" if not self.state.is_primary else "none"
        return ", ".join(offer)

    def begin(self, transition: int | str | LifecycleTransition) -> TransitionDescription:
        """Take a user-visible transition: primary state -> transition state."""
        edge = self.resolve(transition)
        self.state = edge.goal_state
        return edge

    def finish(self, result: TransitionCallbackReturn) -> TransitionDescription:
        """Leave the current transition state according to its hook's ``result``."""
        if self.state.is_primary:
            raise InvalidTransitionError(
                f"{self.owner}: no transition in progress (state {self.state.label!r}) to finish"
            )
        offset = _RESULT_OFFSET[TransitionCallbackReturn(result)]
        edge = [t for t in self.available_transitions()][offset]
        self.state = edge.goal_state
        return edge
