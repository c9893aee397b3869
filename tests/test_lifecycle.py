"""Lifecycle nodes on a runtime: hooks, failures, error processing, lifecycle publishers, services."""

import asyncio
import logging

import pytest

from aiorobot import Node
from aiorobot.lifecycle import (
    InvalidTransitionError,
    LifecycleNode,
    LifecycleState,
    LifecycleTransition,
    TransitionCallbackReturn,
)
from aiorobot.msgs.lifecycle_msgs import (
    ChangeState,
    GetAvailableStates,
    GetAvailableTransitions,
    GetState,
    Transition,
    TransitionEvent,
)
from aiorobot.msgs.std_msgs import Int32
from aiorobot.testing import settle

S = LifecycleState
R = TransitionCallbackReturn


class Recorder(LifecycleNode):
    """Records every hook call; ``results[hook]`` sets what a hook returns (an exception is raised)."""

    def __init__(self, name="managed", **kw):
        super().__init__(name, **kw)
        self.calls = []
        self.results = {}
        self.pub = self.create_lifecycle_publisher(Int32, "/out", 10)

    async def _hook(self, name, state):
        self.calls.append((name, state, self.current_state))
        result = self.results.get(name)
        if isinstance(result, Exception):
            raise result
        return result

    async def on_configure(self, state):
        return await self._hook("configure", state)

    async def on_activate(self, state):
        return await self._hook("activate", state)

    async def on_deactivate(self, state):
        return await self._hook("deactivate", state)

    async def on_cleanup(self, state):
        return await self._hook("cleanup", state)

    async def on_shutdown_transition(self, state):
        return await self._hook("shutdown", state)

    async def on_error(self, state):
        return await self._hook("error", state)


async def test_each_transition_runs_its_hook_in_its_transition_state(runtime):
    node = runtime.add_node(Recorder())
    assert node.current_state is S.UNCONFIGURED
    assert await node.trigger_configure() is S.INACTIVE
    assert await node.trigger_activate() is S.ACTIVE
    assert await node.trigger_deactivate() is S.INACTIVE
    assert await node.trigger_cleanup() is S.UNCONFIGURED
    assert await node.trigger_shutdown() is S.FINALIZED
    assert node.calls == [
        ("configure", S.UNCONFIGURED, S.CONFIGURING),
        ("activate", S.INACTIVE, S.ACTIVATING),
        ("deactivate", S.ACTIVE, S.DEACTIVATING),
        ("cleanup", S.INACTIVE, S.CLEANINGUP),
        ("shutdown", S.UNCONFIGURED, S.SHUTTINGDOWN),
    ]


async def test_trigger_transition_takes_labels_ids_and_enum_members(runtime):
    node = runtime.add_node(Recorder())
    assert await node.trigger_transition("configure") is S.INACTIVE
    assert await node.trigger_transition(int(Transition.TRANSITION_ACTIVATE)) is S.ACTIVE
    assert await node.trigger_transition(LifecycleTransition.ACTIVE_SHUTDOWN) is S.FINALIZED


@pytest.mark.parametrize(
    ("prepare", "hook", "trigger", "back_to"),
    [
        ([], "configure", "configure", S.UNCONFIGURED),
        (["configure"], "activate", "activate", S.INACTIVE),
        (["configure", "activate"], "deactivate", "deactivate", S.ACTIVE),
        (["configure"], "cleanup", "cleanup", S.INACTIVE),
    ],
)
async def test_hook_failure_returns_to_the_previous_state(runtime, prepare, hook, trigger, back_to):
    node = runtime.add_node(Recorder())
    for t in prepare:
        await node.trigger_transition(t)
    node.results[hook] = R.FAILURE
    state, result = await node.change_state(trigger)
    assert state is back_to and node.current_state is back_to
    assert result is R.FAILURE
    assert "error" not in [c[0] for c in node.calls]


async def test_a_hook_that_raises_goes_through_error_processing_to_unconfigured(runtime, caplog):
    node = runtime.add_node(Recorder())
    await node.trigger_configure()
    node.results["activate"] = RuntimeError("camera unplugged")
    with caplog.at_level(logging.ERROR):
        state, result = await node.change_state("activate")
    assert state is S.UNCONFIGURED and result is R.ERROR
    assert node.calls[-1] == ("error", S.INACTIVE, S.ERRORPROCESSING)
    errors = [r for r in caplog.records if r.levelno == logging.ERROR]
    assert "on_activate of /managed raised" in errors[0].getMessage()
    assert "camera unplugged" in str(errors[0].exc_info[1])


@pytest.mark.parametrize("error_result", [R.FAILURE, R.ERROR, ValueError("cannot recover")])
async def test_error_processing_that_fails_finalizes(runtime, error_result):
    node = runtime.add_node(Recorder())
    node.results["configure"] = R.ERROR
    node.results["error"] = error_result
    assert await node.trigger_configure() is S.FINALIZED
    with pytest.raises(InvalidTransitionError, match=r"from state 'finalized'"):
        await node.trigger_configure()


async def test_a_hook_returning_something_else_counts_as_error(runtime, caplog):
    node = runtime.add_node(Recorder())
    node.results["configure"] = True
    with caplog.at_level(logging.ERROR):
        assert await node.trigger_configure() is S.UNCONFIGURED  # via error processing
    assert any("returned True; expected a TransitionCallbackReturn" in r.getMessage() for r in caplog.records)


async def test_invalid_transition_raises_naming_the_state(runtime):
    node = runtime.add_node(Recorder())
    with pytest.raises(
        InvalidTransitionError,
        match=r"^/managed: cannot 'activate' from state 'unconfigured'; valid from 'unconfigured': configure, shutdown$",
    ):
        await node.trigger_activate()
    assert node.current_state is S.UNCONFIGURED and node.calls == []


async def test_a_second_transition_is_refused_while_one_is_in_progress(runtime):
    release = asyncio.Event()

    class Slow(LifecycleNode):
        async def on_configure(self, state):
            await release.wait()

    node = runtime.add_node(Slow("slow"))
    first = asyncio.create_task(node.trigger_configure())
    await settle(runtime)
    assert node.current_state is S.CONFIGURING
    with pytest.raises(InvalidTransitionError, match=r"cannot 'configure' from state 'configuring'"):
        await node.trigger_configure()
    release.set()
    assert await first is S.INACTIVE


async def test_lifecycle_publisher_delivers_only_while_active(runtime, caplog):
    node = runtime.add_node(Recorder())
    probe = runtime.add_node(Node("probe"))
    got = []
    probe.create_subscription(Int32, "/out", lambda m: got.append(m.data), 10)

    async def publish(value):
        node.pub.publish(Int32(data=value))
        await settle(runtime)

    with caplog.at_level(logging.WARNING):
        await publish(1)  # unconfigured
        await publish(2)
        await node.trigger_configure()
        await publish(3)  # inactive
        await node.trigger_activate()
        assert node.pub.is_activated
        await publish(4)  # active
        await node.trigger_deactivate()
        await publish(5)
    assert got == [4]
    assert node.pub.suppressed == 4
    warnings = [r.getMessage() for r in caplog.records if "but the publisher is not activated" in r.getMessage()]
    # Once per deactivated period, as rclcpp: before the activation, and again after it.
    assert len(warnings) == 2
    assert warnings[0].startswith("Trying to publish message on the topic '/out', but the publisher is not activated")


async def test_lifecycle_publisher_is_silent_in_on_deactivate_and_may_be_activated_early(runtime):
    seen = []

    class Node2(LifecycleNode):
        def __init__(self):
            super().__init__("n2")
            self.pub = self.create_lifecycle_publisher(Int32, "/out", 10)

        async def on_activate(self, state):
            self.pub.on_activate()  # publish a first sample before the transition completes
            self.pub.publish(Int32(data=1))

        async def on_deactivate(self, state):
            self.pub.publish(Int32(data=2))

    node = runtime.add_node(Node2())
    probe = runtime.add_node(Node("probe"))
    probe.create_subscription(Int32, "/out", lambda m: seen.append(m.data), 10)
    await node.trigger_configure()
    await node.trigger_activate()
    await node.trigger_deactivate()
    await settle(runtime)
    assert seen == [1]


async def test_transition_events_announce_every_step(runtime):
    node = runtime.add_node(Recorder())
    probe = runtime.add_node(Node("probe"))
    events = []
    probe.create_subscription(TransitionEvent, "/managed/transition_event", events.append, 10)
    node.results["activate"] = R.ERROR
    await node.trigger_configure()
    await node.trigger_activate()
    await settle(runtime)
    steps = [(e.transition.label, e.transition.id, e.start_state.label, e.goal_state.label) for e in events]
    assert steps == [
        ("configure", 1, "unconfigured", "configuring"),
        ("transition_success", 10, "configuring", "inactive"),
        ("activate", 3, "inactive", "activating"),
        ("transition_error", 32, "activating", "errorprocessing"),
        ("transition_success", 60, "errorprocessing", "unconfigured"),
    ]


async def test_services_drive_transitions_from_another_node(runtime):
    node = runtime.add_node(Recorder())
    manager = runtime.add_node(Node("manager"))
    change = manager.create_client(ChangeState, "/managed/change_state")
    get_state = manager.create_client(GetState, "/managed/get_state")
    transitions = manager.create_client(GetAvailableTransitions, "/managed/get_available_transitions")
    assert await change.wait_for_service(timeout_sec=5)

    async def request(label="", id=0):
        response = await change.call(ChangeState.Request(transition=Transition(id=id, label=label)), timeout_sec=5)
        return response.success

    async def state():
        return (await get_state.call(GetState.Request(), timeout_sec=5)).current_state.label

    assert await state() == "unconfigured"
    assert await request(label="configure")
    assert await request(id=Transition.TRANSITION_ACTIVATE)
    assert await state() == "active" and node.current_state is S.ACTIVE
    available = (await transitions.call(GetAvailableTransitions.Request(), timeout_sec=5)).available_transitions
    assert [(t.transition.label, t.goal_state.label) for t in available] == [
        ("deactivate", "deactivating"),
        ("shutdown", "shuttingdown"),
    ]
    assert not await request(label="configure")  # invalid from active: refused
    assert node.current_state is S.ACTIVE
    node.results["deactivate"] = R.FAILURE
    assert not await request(label="deactivate")  # the hook failed
    assert await state() == "active"
    assert await request(label="shutdown")
    assert await state() == "finalized"


async def test_get_state_answers_during_a_transition(runtime):
    release = asyncio.Event()

    class Slow(LifecycleNode):
        async def on_configure(self, state):
            await release.wait()

    runtime.add_node(Slow("slow"))
    manager = runtime.add_node(Node("manager"))
    change = manager.create_client(ChangeState, "/slow/change_state")
    get_state = manager.create_client(GetState, "/slow/get_state")
    assert await change.wait_for_service(timeout_sec=5)
    pending = asyncio.create_task(change.call(ChangeState.Request(transition=Transition(label="configure")), 5))
    await settle(runtime)
    assert (await get_state.call(GetState.Request(), timeout_sec=5)).current_state.label == "configuring"
    release.set()
    assert (await pending).success


async def test_available_states_and_transition_graph_services(runtime):
    runtime.add_node(Recorder())
    manager = runtime.add_node(Node("manager"))
    states = manager.create_client(GetAvailableStates, "/managed/get_available_states")
    graph = manager.create_client(GetAvailableTransitions, "/managed/get_transition_graph")
    assert await states.wait_for_service(timeout_sec=5)
    labels = [s.label for s in (await states.call(GetAvailableStates.Request(), 5)).available_states]
    assert labels[:5] == ["unknown", "unconfigured", "inactive", "active", "finalized"] and len(labels) == 11
    edges = (await graph.call(GetAvailableTransitions.Request(), 5)).available_transitions
    assert len(edges) == 25


async def test_runtime_shutdown_takes_the_shutdown_transition(runtime):
    node = runtime.add_node(Recorder())
    await node.trigger_configure()
    await node.trigger_activate()
    await runtime.__aexit__(None, None, None)
    assert node.current_state is S.FINALIZED
    assert node.calls[-1] == ("shutdown", S.ACTIVE, S.SHUTTINGDOWN)


async def test_without_communication_interface_there_are_no_services(runtime):
    node = runtime.add_node(Recorder(enable_communication_interface=False))
    assert node.lifecycle_services == []
    assert [p.topic_name for p in node.publishers if p.topic_name not in ("/parameter_events", "/rosout")] == ["/out"]


async def test_hooks_of_a_priority_loop_node_run_on_its_loop(runtime):
    import threading

    class OnPriority(LifecycleNode):
        async def on_configure(self, state):
            self.hook_thread = threading.get_ident()

    node = runtime.add_node(OnPriority("prio"), executor="priority")
    assert await node.trigger_configure() is S.INACTIVE
    assert node.hook_thread == node._thread_id != threading.get_ident()
