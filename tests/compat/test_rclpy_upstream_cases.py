"""rclpy's own test cases that aiorobot used to fail (issue 25 item 7), restated on the compat layer.

Each test names the upstream case it restates (ros2/rclpy, rclpy/test/...). They run in this
process on a context of their own, as rclpy's tests do.
"""

from __future__ import annotations

import asyncio
import threading
from collections.abc import Iterator

import pytest

from aiorobot.compat import rclpy
from aiorobot.compat.rclpy.clock import Clock, ClockType
from aiorobot.compat.rclpy.context import Context
from aiorobot.compat.rclpy.exceptions import ROSInterruptException
from aiorobot.compat.rclpy.parameter import Parameter, parameter_value_to_python
from aiorobot.msgs.example_interfaces import AddTwoInts
from aiorobot.msgs.rcl_interfaces import ParameterType, ParameterValue
from aiorobot.msgs.std_msgs import String
from aiorobot.compat.rclpy.time import Time


@pytest.fixture
def node() -> Iterator[object]:
    context = Context()
    rclpy.init(context=context)
    node = rclpy.create_node("test_upstream_cases", context=context)
    try:
        yield node
    finally:
        node.destroy_node()
        rclpy.try_shutdown(context=context)


def test_parameter_value_to_python_takes_rclpys_forms():
    # test_parameter.py::TestParameter::test_parameter_value_to_python
    cases = [
        (ParameterValue(type=int(ParameterType.PARAMETER_NOT_SET)), None),
        (ParameterValue(type=int(ParameterType.PARAMETER_INTEGER), integer_value=42), 42),
        (ParameterValue(type=int(ParameterType.PARAMETER_DOUBLE), double_value=3.5), 3.5),
        (ParameterValue(type=int(ParameterType.PARAMETER_STRING), string_value="foo"), "foo"),
        (ParameterValue(type=int(ParameterType.PARAMETER_BYTE_ARRAY), byte_array_value=[b"J", b"P"]), [b"J", b"P"]),
        (ParameterValue(type=int(ParameterType.PARAMETER_INTEGER_ARRAY), integer_array_value=[1, 2, 3]), [1, 2, 3]),
        (ParameterValue(type=int(ParameterType.PARAMETER_DOUBLE_ARRAY), double_array_value=[1.0, 2.0, 3.0]),
         [1.0, 2.0, 3.0]),
        (ParameterValue(type=int(ParameterType.PARAMETER_STRING_ARRAY), string_array_value=["foo", "bar"]),
         ["foo", "bar"]),
    ]
    for value, expected in cases:
        assert parameter_value_to_python(value) == expected
    with pytest.raises(RuntimeError):
        parameter_value_to_python(ParameterValue(type=42))


def test_a_byte_array_field_refuses_a_list_of_longer_bytes():
    with pytest.raises(TypeError, match=r"byte_array_value expects a sequence of uint8: item 1: expected one-byte bytes"):
        ParameterValue(type=int(ParameterType.PARAMETER_BYTE_ARRAY), byte_array_value=[b"J", b"PP"])


def test_destroy_rate_returns_true_once(node):
    # test_rate.py::TestRate::test_destroy
    rate = node.create_rate(10.0)
    assert node.destroy_rate(rate) is True
    assert node.destroy_rate(rate) is False
    with pytest.raises(RuntimeError, match="destroyed"):
        rate.sleep()


def test_destroy_rate_wakes_a_thread_sleeping_on_it(node):
    # test_rate.py::TestRate::test_destroy_wakes_rate
    rate = node.create_rate(0.0000001)
    sleeper = threading.Thread(target=rate.sleep, daemon=True)
    sleeper.start()
    assert node.destroy_rate(rate)
    sleeper.join(10)
    assert not sleeper.is_alive()


def test_shutdown_wakes_a_rate_with_ros_interrupt():
    # test_rate.py::test_shutdown_wakes_rate (and the sleeper sees ROSInterruptException)
    context = Context()
    rclpy.init(context=context)
    node = rclpy.create_node("test_rate_shutdown", context=context)
    rate = node.create_rate(0.0000001)
    raised: list[BaseException] = []

    def sleep() -> None:
        try:
            rate.sleep()
        except ROSInterruptException as err:
            raised.append(err)

    sleeper = threading.Thread(target=sleep, daemon=True)
    sleeper.start()
    node.destroy_node()
    rclpy.shutdown(context=context)
    sleeper.join(10)
    assert not sleeper.is_alive() and len(raised) == 1


def test_destroy_methods_return_whether_they_destroyed(node):
    # rclpy's Node.destroy_*: True for an entity of the node, False when it is gone already
    entities = [
        (node.destroy_publisher, node.create_publisher(String, "chatter", 1)),
        (node.destroy_subscription, node.create_subscription(String, "chatter", lambda msg: None, 1)),
        (node.destroy_timer, node.create_timer(1.0, lambda: None)),
        (node.destroy_service, node.create_service(AddTwoInts, "add", lambda req, res: res)),
        (node.destroy_client, node.create_client(AddTwoInts, "add")),
        (node.destroy_guard_condition, node.create_guard_condition(lambda: None)),
    ]
    for destroy, entity in entities:
        assert destroy(entity) is True, destroy
        assert destroy(entity) is False, destroy


def test_sleep_until_with_another_clock_type_says_clock_type_does_not_match():
    # test_clock.py::test_sleep_until_mismatched_clock_type: raised at the call
    clock = Clock(clock_type=ClockType.SYSTEM_TIME)
    with pytest.raises(ValueError, match=".*clock type does not match.*"):
        clock.sleep_until(Time(clock_type=ClockType.STEADY_TIME))


def test_invalid_names_in_graph_queries_say_is_invalid(node):
    # test_node.py::TestNode::test_count_clients_services, ::test_count_publishers_subscribers,
    # ::test_get_publishers_subscriptions_info_by_topic (error cases)
    for query in (node.count_clients, node.count_services, node.count_publishers, node.count_subscribers):
        with pytest.raises(TypeError):
            query(1)
        with pytest.raises(ValueError, match="is invalid"):
            query("42")
    for info in (node.get_subscriptions_info_by_topic, node.get_publishers_info_by_topic):
        with pytest.raises(ValueError, match="is invalid"):
            info("13")


def test_an_empty_pre_set_result_is_refused_with_rclpys_reason(node):
    # test_node.py::TestNode::test_node_set_parameters_pre_set_callback (the empty-list case)
    node.declare_parameter("foo", 0)
    empty = lambda parameters: []  # noqa: E731
    node.add_pre_set_parameters_callback(empty)
    results = node.set_parameters([Parameter("foo", Parameter.Type.INTEGER, 42)])
    node.remove_pre_set_parameters_callback(empty)
    assert not results[0].successful
    assert results[0].reason == (
        "parameter list cannot be empty, this might be due to "
        "pre_set_parameters_callback modifying the original parameters list."
    )
    assert node.get_parameter("foo").value == 0


async def test_destroy_rate_wakes_a_task_sleeping_on_it():
    # the asyncio form of test_destroy_wakes_rate, on aiorobot's own Rate, from the loop and from a thread
    from aiorobot import Node, Runtime

    async with Runtime() as runtime:
        node = runtime.add_node(Node("rates"))
        for destroy_from_thread in (False, True):
            rate = node.create_rate(0.0000001)
            sleeper = asyncio.ensure_future(rate.sleep())
            await asyncio.sleep(0)  # it is asleep
            if destroy_from_thread:
                result: list[bool] = []
                thread = threading.Thread(target=lambda r=rate: result.append(node.destroy_rate(r)))
                thread.start()
                await asyncio.to_thread(thread.join)
                assert result == [True]
            else:
                assert node.destroy_rate(rate) is True
            await asyncio.wait_for(sleeper, 10)
            assert node.destroy_rate(rate) is False
            with pytest.raises(RuntimeError, match="destroyed"):
                await rate.sleep()


def _wait(predicate, what: str) -> None:
    import time

    deadline = time.monotonic() + 10  # a generous bound on what a spinning thread does at once
    while not predicate():
        assert time.monotonic() < deadline, what
        time.sleep(0.001)


def test_a_rate_follows_sim_time_under_use_sim_time():
    # rclpy's Node.create_rate makes a timer on the node's clock: under use_sim_time, /clock paces it
    from aiorobot.compat.rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
    from aiorobot.msgs.rosgraph_msgs import Clock as ClockMsg

    context = Context()
    rclpy.init(context=context)
    node = rclpy.create_node("sim_rate", context=context, parameter_overrides=[Parameter("use_sim_time", value=True)])
    clock_pub = node.create_publisher(ClockMsg, "/clock", 10)
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(node)

    def spin() -> None:
        try:
            executor.spin()
        except ExternalShutdownException:
            pass

    spinner = threading.Thread(target=spin)
    spinner.start()

    def set_sim_time(sec: int) -> None:
        clock_pub.publish(ClockMsg(clock=Time(seconds=sec).to_msg()))
        _wait(lambda: node.get_clock().now().nanoseconds == sec * 10**9, f"sim time never read {sec} s")

    woke_at: list[int] = []
    try:
        set_sim_time(100)
        rate = node.create_rate(1e-4)  # a period of 10,000 s of sim time (the wall clock would never get there)
        sleeper = threading.Thread(target=lambda: (rate.sleep(), woke_at.append(node.get_clock().now().nanoseconds)))
        sleeper.start()
        set_sim_time(5_000)
        assert sleeper.is_alive() and not woke_at  # half a period of sim time later
        set_sim_time(10_101)
        sleeper.join(10)
        assert not sleeper.is_alive() and woke_at and woke_at[0] >= 10_100 * 10**9
    finally:
        executor.shutdown()
        spinner.join(10)
        node.destroy_node()
        rclpy.try_shutdown(context=context)
