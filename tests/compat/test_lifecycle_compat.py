"""``rclpy.lifecycle`` on aiorobot: the upstream lifecycle talker under ``aiorobot exec``, and the
synchronous API restated from rclpy's test_lifecycle.py (no mocks: real publishers and services)."""

from __future__ import annotations

import logging

import pytest

import aiorobot.compat.rclpy as rclpy
from aiorobot.compat._context import Context
from aiorobot.compat.rclpy.executors import SingleThreadedExecutor
from aiorobot.compat.rclpy.lifecycle import (
    LifecycleNode,
    LifecycleNodeMixin,
    LifecyclePublisher,
    ManagedEntity,
    SimpleManagedEntity,
    State,
    TransitionCallbackReturn,
)
from aiorobot.compat.rclpy.node import Node
from aiorobot.msgs import lifecycle_msgs
from aiorobot.msgs.std_msgs import String

from ._run import Program

SUCCESS = TransitionCallbackReturn.SUCCESS
FAILURE = TransitionCallbackReturn.FAILURE
ERROR = TransitionCallbackReturn.ERROR


# -- the upstream program -----------------------------------------------------------------------------


def test_upstream_lifecycle_talker_walks_its_states_driven_by_its_lifecycle_services():
    """lifecycle_py/talker.py, unmodified; a native node calls /lc_talker/change_state and get_state
    (as the demo's README does with ``ros2 lifecycle set``) and listens on /lifecycle_chatter."""
    program = Program("lifecycle_py/talker.py", nodes=("LifecycleTalkerDriver",))
    program.wait_for("driver: done")
    code = program.stop()
    out = program.lines

    def index(needle: str) -> int:
        hits = [i for i, line in enumerate(out) if needle in line]
        assert hits, f"{needle!r} not in the output:\n{program.output}"
        return hits[0]

    assert "driver: state unconfigured" in out
    # not offered from 'unconfigured': refused, as rcl_lifecycle refuses it
    assert "driver: activate -> success False, state unconfigured" in out
    assert index("Unable to start transition activate from current state (1, 'unconfigured')") < index(
        "on_configure() is called."
    )
    assert "driver: configure -> success True, state inactive" in out
    # the transition events the demo's lc_listener prints
    assert "native notify callback: Transition from state unconfigured to configuring" in out
    assert "native notify callback: Transition from state configuring to inactive" in out
    assert "native notify callback: Transition from state shuttingdown to finalized" in out
    assert "driver: activate -> success True, state active" in out
    # active: the talker says it publishes, and the native listener hears exactly that
    assert index("on_activate() is called.") < index(
        "Lifecycle publisher is active. Publishing: [Lifecycle HelloWorld #0]"
    )
    assert index("Publishing: [Lifecycle HelloWorld #1]") < index("native heard: Lifecycle HelloWorld #1")
    assert "native heard: Lifecycle HelloWorld #0" in out
    # deactivated: the talker's timer goes on, its publisher says it is inactive, nothing arrives
    assert "driver: deactivate -> success True, state inactive" in out
    assert index("on_deactivate() is called.") < index("Lifecycle publisher is inactive. Messages are not published.")
    assert "driver: heard 0 while inactive" in out
    assert not [line for line in out[index("on_deactivate() is called.") :] if "Publishing:" in line]
    assert "driver: cleanup -> success True, state unconfigured" in out
    assert index("on_cleanup() is called.") < index("on_shutdown() is called.")
    assert "driver: shutdown -> success True, state finalized" in out
    assert code == 0, f"exit status {code}; output:\n{program.output}"
    assert "Traceback" not in program.output, program.output


# -- the synchronous API (rclpy's test_lifecycle.py) ---------------------------------------------------


@pytest.fixture
def context():
    ctx = Context()
    rclpy.init(args=[], context=ctx)
    yield ctx
    ctx.try_shutdown()


def state_label(node: LifecycleNode) -> str:
    return node._state_machine.current_state[1]


def test_lifecycle_node_init_creates_the_services_unless_told_not_to(context):
    node = LifecycleNode("test_lifecycle_node_init_1", context=context)
    assert node._service_change_state.srv_name == "/test_lifecycle_node_init_1/change_state"
    assert node._state_machine.service_get_transition_graph is node._service_get_transition_graph
    node.destroy_node()
    node = LifecycleNode("test_lifecycle_node_init_2", context=context, enable_communication_interface=False)
    for name in (
        "change_state", "get_state", "get_available_states", "get_available_transitions", "get_transition_graph"
    ):
        assert not hasattr(node, f"_service_{name}")
        assert not getattr(node._state_machine, f"service_{name}")
    node.destroy_node()
    with pytest.raises(TypeError):
        LifecycleNode("test_lifecycle_node_init_3", context=context, enable_communication_interface="asd")


def test_lifecycle_state_transitions_return_the_callbacks_result(context):
    node = LifecycleNode("test_lifecycle_state_transitions_1", context=context, enable_communication_interface=False)
    assert node.trigger_configure() == SUCCESS
    for _ in range(10):
        assert node.trigger_cleanup() == SUCCESS
        assert node.trigger_configure() == SUCCESS
    for _ in range(10):
        assert node.trigger_activate() == SUCCESS
        assert node.trigger_deactivate() == SUCCESS
    assert node.trigger_cleanup() == SUCCESS
    assert node.trigger_shutdown() == SUCCESS
    assert state_label(node) == "finalized"
    node.destroy_node()
    node = LifecycleNode("test_lifecycle_state_transitions_2", context=context, enable_communication_interface=False)
    assert node.trigger_configure() == SUCCESS
    assert node.trigger_shutdown() == SUCCESS  # from 'inactive'
    node = LifecycleNode("test_lifecycle_state_transitions_3", context=context, enable_communication_interface=False)
    assert node.trigger_configure() == SUCCESS
    assert node.trigger_activate() == SUCCESS
    assert node.trigger_shutdown() == SUCCESS  # from 'active'
    assert state_label(node) == "finalized"


def test_a_callback_that_raises_takes_the_error_path_and_on_error_decides(context):
    class ErrorOnConfigureHandledCorrectlyNode(LifecycleNode):
        def on_configure(self):  # wrong signature, as upstream's test: calling it raises
            return TransitionCallbackReturn.ERROR

    node = ErrorOnConfigureHandledCorrectlyNode("handled", context=context, enable_communication_interface=False)
    assert state_label(node) == "unconfigured"
    assert node.trigger_configure() == ERROR
    assert state_label(node) == "unconfigured"  # the default on_error returned SUCCESS

    class ErrorOnConfigureHandledInCorrectlyNode(LifecycleNode):
        def on_configure(self):
            return TransitionCallbackReturn.ERROR

        def on_error(self):
            return TransitionCallbackReturn.ERROR

    node = ErrorOnConfigureHandledInCorrectlyNode("unhandled", context=context, enable_communication_interface=False)
    assert node.trigger_configure() == ERROR
    assert state_label(node) == "finalized"


def test_failure_returns_to_the_start_state_and_error_runs_on_error_with_the_start_state(context):
    seen = []

    class Picky(LifecycleNode):
        def on_configure(self, state):
            seen.append(("on_configure", state))
            return TransitionCallbackReturn.SUCCESS

        def on_activate(self, state):
            seen.append(("on_activate", state))
            return TransitionCallbackReturn.FAILURE

        def on_cleanup(self, state):
            seen.append(("on_cleanup", state))
            return TransitionCallbackReturn.ERROR

        def on_error(self, state):
            seen.append(("on_error", state))
            return TransitionCallbackReturn.SUCCESS

    node = Picky("picky", context=context, enable_communication_interface=False)
    assert node.trigger_configure() == SUCCESS
    assert node.trigger_activate() == FAILURE
    assert state_label(node) == "inactive"
    assert node.trigger_cleanup() == ERROR
    assert state_label(node) == "unconfigured"
    assert seen == [
        ("on_configure", State(label="unconfigured", state_id=1)),
        ("on_activate", State(label="inactive", state_id=2)),
        ("on_cleanup", State(label="inactive", state_id=2)),
        ("on_error", State(label="inactive", state_id=2)),
    ]


def test_a_transition_the_state_does_not_offer_returns_error_and_changes_nothing(context, caplog):
    node = LifecycleNode("invalid", context=context, enable_communication_interface=False)
    with caplog.at_level(logging.ERROR):
        assert node.trigger_activate() == ERROR
    assert state_label(node) == "unconfigured"
    assert [r.getMessage() for r in caplog.records] == [
        "Unable to start transition 3 from current state (1, 'unconfigured'): /invalid: cannot 'activate' from "
        "state 'unconfigured'; valid from 'unconfigured': configure, shutdown"
    ]
    assert node.trigger_deactivate() == ERROR
    assert node.trigger_cleanup() == ERROR
    assert node.trigger_shutdown() == SUCCESS
    assert node.trigger_configure() == ERROR
    with pytest.raises(RuntimeError, match=r"^Shutdown transtion not possible: /invalid is 'finalized'; shutdown is "
                       r"possible from 'unconfigured', 'inactive' or 'active'$"):
        node.trigger_shutdown()


def test_a_callback_returning_something_else_is_an_error_that_says_so(context, caplog):
    class Forgetful(LifecycleNode):
        def on_configure(self, state):
            pass  # no return

    node = Forgetful("forgetful", context=context, enable_communication_interface=False)
    with caplog.at_level(logging.ERROR):
        assert node.trigger_configure() == ERROR
    assert state_label(node) == "unconfigured"
    assert caplog.records[0].getMessage() == (
        "on_configure() of /forgetful returned None; expected TransitionCallbackReturn.SUCCESS, FAILURE or ERROR. "
        "Treating it as ERROR"
    )


def test_lifecycle_services_answer_as_rclpy(context):
    lc_node_name = "test_lifecycle_services_lifecycle"
    lc_node = LifecycleNode(lc_node_name, context=context)
    client_node = Node("test_lifecycle_services_client", context=context)
    get_state_cli = client_node.create_client(lifecycle_msgs.GetState, f"/{lc_node_name}/get_state")
    change_state_cli = client_node.create_client(lifecycle_msgs.ChangeState, f"/{lc_node_name}/change_state")
    get_available_states_cli = client_node.create_client(
        lifecycle_msgs.GetAvailableStates, f"/{lc_node_name}/get_available_states"
    )
    get_available_transitions_cli = client_node.create_client(
        lifecycle_msgs.GetAvailableTransitions, f"/{lc_node_name}/get_available_transitions"
    )
    get_transition_graph_cli = client_node.create_client(
        lifecycle_msgs.GetAvailableTransitions, f"/{lc_node_name}/get_transition_graph"
    )
    for cli in (get_state_cli, change_state_cli, get_available_states_cli, get_available_transitions_cli,
                get_transition_graph_cli):
        assert cli.wait_for_service(5.0)
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(client_node)
    executor.add_node(lc_node)

    assert get_state_cli.call(lifecycle_msgs.GetState.Request()).current_state.label == "unconfigured"
    request = lifecycle_msgs.ChangeState.Request()
    request.transition.id = lifecycle_msgs.Transition.TRANSITION_CONFIGURE
    assert change_state_cli.call(request).success
    assert get_state_cli.call(lifecycle_msgs.GetState.Request()).current_state.label == "inactive"
    response = get_available_states_cli.call(lifecycle_msgs.GetAvailableStates.Request())
    assert {state.label for state in response.available_states} == {
        "unknown", "unconfigured", "inactive", "active", "finalized", "configuring", "cleaningup",
        "shuttingdown", "activating", "deactivating", "errorprocessing",
    }
    response = get_available_transitions_cli.call(lifecycle_msgs.GetAvailableTransitions.Request())
    assert {t.transition.label for t in response.available_transitions} == {"activate", "cleanup", "shutdown"}
    response = get_transition_graph_cli.call(lifecycle_msgs.GetAvailableTransitions.Request())
    assert {t.transition.label for t in response.available_transitions} == {
        "configure", "activate", "cleanup", "shutdown", "deactivate", "transition_error",
        "transition_failure", "transition_success",
    }
    request = lifecycle_msgs.ChangeState.Request()
    request.transition.id = lifecycle_msgs.Transition.TRANSITION_DEACTIVATE  # not from 'inactive'
    assert not change_state_cli.call(request).success
    assert state_label(lc_node) == "inactive"


def spin_until(context: Context, executor: SingleThreadedExecutor, done) -> None:
    """Spin until ``done()``; generous bound (the machine is shared)."""
    assert context.spin_until(executor, done, 10.0, raise_on_shutdown=True), "condition not reached within 10 s"


def test_lifecycle_publisher_delivers_only_while_activated(context):
    node = LifecycleNode("test_lifecycle_publisher", context=context, enable_communication_interface=False)
    listener = Node("test_lifecycle_listener", context=context)
    heard: list[str] = []
    listener.create_subscription(String, "test_lifecycle_publisher_topic", lambda m: heard.append(m.data), 10)
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(node)
    executor.add_node(listener)
    pub = node.create_lifecycle_publisher(String, "test_lifecycle_publisher_topic", 10)
    assert isinstance(pub, LifecyclePublisher) and pub.topic_name == "/test_lifecycle_publisher_topic"
    assert not pub.is_activated
    pub.publish(String(data="unconfigured"))
    assert node.trigger_configure() == SUCCESS
    pub.publish(String(data="inactive"))
    assert node.trigger_activate() == SUCCESS
    assert pub.is_activated
    pub.publish(String(data="active"))
    spin_until(context, executor, lambda: heard)
    assert node.trigger_deactivate() == SUCCESS
    pub.publish(String(data="deactivated"))
    node.trigger_activate()
    pub.publish(String(data="active again"))
    spin_until(context, executor, lambda: len(heard) == 2)
    assert heard == ["active", "active again"]


def test_overriding_on_activate_without_super_leaves_the_publishers_inactive_as_rclpy(context):
    class NoSuper(LifecycleNode):
        def on_activate(self, state):
            return TransitionCallbackReturn.SUCCESS

    node = NoSuper("no_super", context=context, enable_communication_interface=False)
    pub = node.create_lifecycle_publisher(String, "no_super", 10)
    node.trigger_configure()
    assert node.trigger_activate() == SUCCESS and state_label(node) == "active"
    assert not pub.is_activated


def test_managed_entities_follow_the_transitions_and_the_first_non_success_wins(context):
    class Refuses(ManagedEntity):
        def on_configure(self, state):
            return TransitionCallbackReturn.FAILURE

    node = LifecycleNode("managed", context=context, enable_communication_interface=False)
    flag = SimpleManagedEntity()
    node.add_managed_entity(flag)
    node.trigger_configure()
    node.trigger_activate()
    assert flag.is_activated
    node.trigger_deactivate()
    assert not flag.is_activated
    node.trigger_cleanup()
    node.add_managed_entity(Refuses())
    assert node.trigger_configure() == FAILURE
    assert state_label(node) == "unconfigured"
    with pytest.raises(TypeError, match=r"^Expected a rclpy.lifecycle.ManagedEntity instance.$"):
        node.add_managed_entity(object())


def test_when_enabled_runs_the_method_only_while_activated():
    calls: list[str] = []

    class Gate(SimpleManagedEntity):
        @SimpleManagedEntity.when_enabled(when_not_enabled=lambda: calls.append("refused"))
        def work(self, what: str) -> None:
            calls.append(what)

    gate = Gate()
    gate.work("a")
    gate.on_activate(State("activating", 13))
    gate.work("b")
    gate.on_deactivate(State("deactivating", 14))
    gate.work("c")
    assert calls == ["refused", "b", "refused"]


def test_context_shutdown_takes_no_transition_as_rclpy(context):
    calls: list[str] = []

    class Talker(LifecycleNode):
        def on_shutdown(self, state):
            calls.append("on_shutdown")
            return TransitionCallbackReturn.SUCCESS

    node = Talker("talker", context=context)
    node.trigger_configure()
    rclpy.shutdown(context=context)
    assert calls == [] and state_label(node) == "inactive"


def test_the_mixin_needs_the_lifecycle_node_underneath(context):
    class Mixed(LifecycleNodeMixin, Node):
        def __init__(self) -> None:
            Node.__init__(self, "mixed", context=context)
            LifecycleNodeMixin.__init__(self)

    with pytest.raises(RuntimeError, match=r"^LifecycleNodeMixin: Mixed combines it with a plain Node; on aiorobot"):
        Mixed()


def test_rclpy_lifecycle_names_and_aliases():
    import aiorobot.compat.rclpy.lifecycle as lifecycle

    assert lifecycle.Node is LifecycleNode and lifecycle.State is lifecycle.LifecycleState
    assert lifecycle.Publisher is LifecyclePublisher and lifecycle.NodeMixin is LifecycleNodeMixin
    assert [r.to_label() for r in (SUCCESS, FAILURE, ERROR)] == [
        "transition_success", "transition_failure", "transition_error"
    ]
    assert int(SUCCESS) == lifecycle_msgs.Transition.TRANSITION_CALLBACK_SUCCESS
