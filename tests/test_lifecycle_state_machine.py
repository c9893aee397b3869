"""The pure lifecycle state machine: rcl_lifecycle's default states, edges, ids and labels."""

import pytest

from aiorobot.lifecycle import (
    TRANSITIONS,
    InvalidTransitionError,
    LifecycleState,
    LifecycleStateMachine,
    LifecycleTransition,
    TransitionCallbackReturn,
)
from aiorobot.msgs.lifecycle_msgs import State, Transition

S = LifecycleState
T = LifecycleTransition
R = TransitionCallbackReturn


def test_ids_match_lifecycle_msgs_constants():
    for state in S:
        prefix = "PRIMARY_STATE_" if state.is_primary else "TRANSITION_STATE_"
        assert getattr(State, prefix + state.name) == state
    for transition in T:
        assert getattr(Transition, "TRANSITION_" + transition.name) == transition
    for result in R:
        assert getattr(Transition, "TRANSITION_CALLBACK_" + result.name) == result


def test_labels_are_rcl_labels():
    assert [s.label for s in (S.UNCONFIGURED, S.CLEANINGUP, S.ERRORPROCESSING)] == [
        "unconfigured",
        "cleaningup",
        "errorprocessing",
    ]
    assert T.CONFIGURE.label == "configure"
    assert {T.UNCONFIGURED_SHUTDOWN.label, T.INACTIVE_SHUTDOWN.label, T.ACTIVE_SHUTDOWN.label} == {"shutdown"}
    assert [T.ON_ACTIVATE_SUCCESS.label, T.ON_ACTIVATE_FAILURE.label, T.ON_ERROR_ERROR.label] == [
        "transition_success",
        "transition_failure",
        "transition_error",
    ]
    assert T.ACTIVATE.to_msg() == Transition(id=3, label="activate")
    assert S.ACTIVE.to_msg() == State(id=3, label="active")


def test_every_transition_state_has_exactly_three_results():
    for state in S:
        edges = [t for t in TRANSITIONS if t.start_state is state]
        if state.is_primary:
            assert all(t.transition < 10 for t in edges)
        else:
            assert [t.transition % 10 for t in edges] == [0, 1, 2]


@pytest.mark.parametrize(
    ("start", "transition", "middle", "success", "failure"),
    [
        (S.UNCONFIGURED, "configure", S.CONFIGURING, S.INACTIVE, S.UNCONFIGURED),
        (S.INACTIVE, "cleanup", S.CLEANINGUP, S.UNCONFIGURED, S.INACTIVE),
        (S.INACTIVE, "activate", S.ACTIVATING, S.ACTIVE, S.INACTIVE),
        (S.ACTIVE, "deactivate", S.DEACTIVATING, S.INACTIVE, S.ACTIVE),
        (S.UNCONFIGURED, "shutdown", S.SHUTTINGDOWN, S.FINALIZED, S.FINALIZED),
        (S.INACTIVE, "shutdown", S.SHUTTINGDOWN, S.FINALIZED, S.FINALIZED),
        (S.ACTIVE, "shutdown", S.SHUTTINGDOWN, S.FINALIZED, S.FINALIZED),
    ],
)
def test_transition_goes_through_its_transition_state(start, transition, middle, success, failure):
    for result, goal in ((R.SUCCESS, success), (R.FAILURE, failure), (R.ERROR, S.ERRORPROCESSING)):
        machine = LifecycleStateMachine()
        machine.state = start
        assert machine.begin(transition).goal_state is middle
        assert machine.state is middle
        machine.finish(result)
        assert machine.state is goal


@pytest.mark.parametrize(("result", "goal"), [(R.SUCCESS, S.UNCONFIGURED), (R.FAILURE, S.FINALIZED), (R.ERROR, S.FINALIZED)])
def test_error_processing_recovers_or_finalizes(result, goal):
    machine = LifecycleStateMachine()
    machine.begin("configure")
    machine.finish(R.ERROR)
    assert machine.state is S.ERRORPROCESSING
    edge = machine.finish(result)
    assert machine.state is goal and edge.transition == 60 + result % 10 - 7


def test_transitions_by_id_and_shutdown_by_any_shutdown_id():
    machine = LifecycleStateMachine()
    machine.begin(1)
    machine.finish(R.SUCCESS)
    edge = machine.begin(int(T.ACTIVE_SHUTDOWN))  # any shutdown id picks this state's shutdown
    assert edge.transition is T.INACTIVE_SHUTDOWN and machine.state is S.SHUTTINGDOWN


def test_invalid_transition_names_the_state_and_what_is_valid():
    machine = LifecycleStateMachine("/camera")
    with pytest.raises(
        InvalidTransitionError,
        match=r"^/camera: cannot 'activate' from state 'unconfigured'; valid from 'unconfigured': configure, shutdown$",
    ):
        machine.begin("activate")
    assert machine.state is S.UNCONFIGURED


def test_no_transition_while_one_is_in_progress():
    machine = LifecycleStateMachine("/camera")
    machine.begin("configure")
    with pytest.raises(InvalidTransitionError, match=r"from state 'configuring'.*wait for it to finish"):
        machine.begin("configure")


def test_nothing_leaves_finalized():
    machine = LifecycleStateMachine("/n")
    machine.begin("shutdown")
    machine.finish(R.SUCCESS)
    assert machine.available_transitions() == []
    with pytest.raises(InvalidTransitionError, match=r"^/n: cannot 'configure' from state 'finalized'; valid from 'finalized': none$"):
        machine.begin("configure")


def test_unknown_and_result_transitions_cannot_be_requested():
    machine = LifecycleStateMachine("/n")
    with pytest.raises(InvalidTransitionError, match=r"^/n: unknown transition 'launch'"):
        machine.begin("launch")
    with pytest.raises(InvalidTransitionError, match=r"^/n: unknown transition id 77"):
        machine.begin(77)
    with pytest.raises(InvalidTransitionError, match=r"follows a hook's result and cannot be requested"):
        machine.begin(int(T.ON_CONFIGURE_SUCCESS))
    with pytest.raises(InvalidTransitionError, match=r"no transition in progress \(state 'unconfigured'\)"):
        machine.finish(R.SUCCESS)
    with pytest.raises(TypeError, match=r"expected an id \(int\) or a label \(str\), got 1\.0"):
        machine.begin(1.0)
