"""rclpy.experimental.AsyncNode (rclpy 10/11's asyncio node) on aiorobot (issue 25 item 7).

Restates cases of ros2/rclpy's rclpy/test/test_async_node.py on the compat layer (each test
names its case), plus actions, which rclpy's AsyncNode lacks. The tests run on pytest's loop,
as rclpy's do, with a context of their own; an ``aiorobot exec`` run of such a program is
test_an_async_node_program_runs_under_aiorobot_exec.
"""

from __future__ import annotations

import asyncio
import textwrap
import threading
from collections.abc import Iterator
from pathlib import Path

import pytest

from aiorobot.compat import rclpy
from aiorobot.compat.rclpy.action import ActionClient, ActionServer
from aiorobot.compat.rclpy.context import Context
from aiorobot.compat.rclpy.experimental import AsyncNode
from aiorobot.msgs.example_interfaces import AddTwoInts, Fibonacci
from aiorobot.msgs.rcl_interfaces import GetParameters, ParameterType
from aiorobot.msgs.std_msgs import String

from ._run import Program


@pytest.fixture
def context() -> Iterator[Context]:
    context = Context()
    rclpy.init(context=context)
    try:
        yield context
    finally:
        rclpy.try_shutdown(context=context)


async def test_lifecycle(context):
    # test_async_node.py::test_lifecycle
    async with AsyncNode("test_lifecycle_node", context=context):
        pass


async def test_destroying_a_subscription_stops_delivery(context):
    # ::test_direct_entity_destroy
    received = asyncio.Event()

    async def callback(msg: String) -> None:
        received.set()

    async with AsyncNode("direct_destroy", context=context) as node:
        pub = node.create_publisher(String, "/direct_destroy_topic", 10)
        sub = node.create_subscription(String, "/direct_destroy_topic", callback, 10)
        pub.publish(String(data="before"))
        async with asyncio.timeout(5):
            await received.wait()
        received.clear()
        assert node.destroy_subscription(sub)
        pub.publish(String(data="after"))
        with pytest.raises(TimeoutError):
            async with asyncio.timeout(0.3):
                await received.wait()


async def test_entities_made_before_entering_dispatch_after_entry(context):
    # ::test_create_before_aenter (a plain-function callback, which AsyncNode also takes)
    heard: list[tuple[str, int]] = []
    received = asyncio.Event()
    node = AsyncNode("pre_aenter", context=context)
    pub = node.create_publisher(String, "/pre_aenter_topic", 10)

    def callback(msg: String) -> None:
        heard.append((msg.data, threading.get_ident()))
        received.set()

    node.create_subscription(String, "/pre_aenter_topic", callback, 10)
    async with node:
        pub.publish(String(data="hello"))
        async with asyncio.timeout(5):
            await received.wait()
    assert heard == [("hello", threading.get_ident())]  # on the program's loop, as rclpy's AsyncNode


async def test_two_nodes_talk_both_ways(context):
    # ::test_multiple_entities_two_nodes
    received_a, received_b = asyncio.Event(), asyncio.Event()
    async with AsyncNode("multi_a", context=context) as a, AsyncNode("multi_b", context=context) as b:
        pub_a = a.create_publisher(String, "/multi_a", 10)
        b.create_subscription(String, "/multi_a", lambda m: received_a.set(), 10)
        pub_b = b.create_publisher(String, "/multi_b", 10)
        a.create_subscription(String, "/multi_b", lambda m: received_b.set(), 10)
        async with asyncio.timeout(5):
            while pub_a.get_subscription_count() < 1 or pub_b.get_subscription_count() < 1:
                await asyncio.sleep(0.05)
        pub_a.publish(String(data="a"))
        pub_b.publish(String(data="b"))
        async with asyncio.timeout(5):
            await received_a.wait()
            await received_b.wait()


async def test_a_service_and_an_awaited_client(context):
    # rclpy's AsyncService / AsyncClient: await wait_for_service(), await call(request)
    async def add(request, response):
        response.sum = request.a + request.b
        return response

    async with AsyncNode("adder", context=context) as server, AsyncNode("caller", context=context) as caller:
        server.create_service(AddTwoInts, "add", add)
        client = caller.create_client(AddTwoInts, "/add")
        async with asyncio.timeout(5):
            await client.wait_for_service()
            assert (await client.call(AddTwoInts.Request(a=2, b=40))).sum == 42


async def test_parameter_services_answer_another_async_node(context):
    # ::test_parameter_service_over_dds (the get half)
    async with AsyncNode("param_srv", context=context) as srv_node, AsyncNode("param_cli", context=context) as cli_node:
        srv_node.declare_parameter("my_param", 42)
        client = cli_node.create_client(GetParameters, "/param_srv/get_parameters")
        async with asyncio.timeout(5):
            await client.wait_for_service()
            response = await client.call(GetParameters.Request(names=["my_param"]))
        assert response.values[0].type == ParameterType.PARAMETER_INTEGER
        assert response.values[0].integer_value == 42


async def test_the_logger_service_answers_another_async_node(context):
    # ::test_enable_logger_service
    from aiorobot.msgs.rcl_interfaces import GetLoggerLevels

    async with AsyncNode("logger_svc", enable_logger_service=True, context=context) as srv_node, \
            AsyncNode("logger_cli", context=context) as cli_node:
        client = cli_node.create_client(GetLoggerLevels, "/logger_svc/get_logger_levels")
        name = srv_node.get_logger().name
        async with asyncio.timeout(5):
            await client.wait_for_service()
            response = await client.call(GetLoggerLevels.Request(names=[name]))
        assert [level.name for level in response.levels] == [name]


async def test_run_returns_when_destroyed(context):
    # ::test_run_basic
    node = AsyncNode("run_node", context=context)
    asyncio.get_running_loop().call_later(0.1, node.destroy_node)
    async with asyncio.timeout(5):
        await node.run()


async def test_run_returns_when_a_callback_destroys_the_node(context):
    # ::test_run_with_callback_shutdown
    received = asyncio.Event()
    node = AsyncNode("run_cb_shutdown", context=context)

    async def callback(msg: String) -> None:
        received.set()
        node.destroy_node()

    pub = node.create_publisher(String, "/run_cb_topic", 10)
    node.create_subscription(String, "/run_cb_topic", callback, 10)
    asyncio.get_running_loop().call_later(0.1, pub.publish, String(data="stop"))
    async with asyncio.timeout(5):
        await node.run()
    assert received.is_set()


async def test_run_raises_if_already_running(context):
    # ::test_run_raises_if_already_running
    async with AsyncNode("run_conflict", context=context) as node:
        with pytest.raises(RuntimeError):
            await node.run()


async def test_wait_for_node(context):
    # ::test_wait_for_node_async, ::test_wait_for_node_async_timeout
    async with AsyncNode("wfn_target", namespace="/ns", context=context), \
            AsyncNode("wfn_watcher", namespace="/ns", context=context) as watcher:
        async with asyncio.timeout(3):
            await watcher.wait_for_node("/ns/wfn_target")
        with pytest.raises(TimeoutError):
            async with asyncio.timeout(0.3):
                await watcher.wait_for_node("nonexistent_node")


async def test_a_destroyed_node_refuses_new_entities_and_destroy_is_idempotent(context):
    # ::test_create_*_on_destroyed_node, ::test_destroy_node_idempotent
    node = AsyncNode("destroyed", context=context)
    node.destroy_node()
    node.destroy_node()
    for make in (
        lambda: node.create_publisher(String, "/topic", 10),
        lambda: node.create_subscription(String, "/topic", lambda m: None, 10),
        lambda: node.create_client(AddTwoInts, "/service"),
        lambda: node.create_timer(1.0, lambda: None),
    ):
        with pytest.raises(RuntimeError, match="destroyed node"):
            make()


async def test_an_exception_in_the_body_destroys_the_node(context):
    # ::test_aexit_destroys_on_exception
    node = AsyncNode("aexit_exc", context=context)
    node.create_publisher(String, "/topic", 10)
    with pytest.raises(ExceptionGroup) as info:
        async with node:
            raise RuntimeError("user error")
    assert info.value.subgroup(RuntimeError)
    with pytest.raises(RuntimeError):
        node.create_publisher(String, "/topic", 10)


async def test_a_timer_and_the_clock_sleep(context):
    # rclpy's AsyncTimer (callback with or without TimerInfo) and AsyncClock.sleep
    plain: list[int] = []
    infos: list[object] = []
    async with AsyncNode("timers", context=context) as node:
        node.create_timer(0.02, lambda: plain.append(1))
        node.create_timer(0.02, lambda info: infos.append(info))
        async with asyncio.timeout(5):
            while len(plain) < 2 or len(infos) < 2:
                await node.get_clock().sleep(0.02)
    assert all(type(i).__name__ == "TimerInfo" for i in infos)


async def test_actions_on_async_nodes(context):
    # beyond rclpy's AsyncNode: an action server and an awaited action client
    async def execute(goal_handle):
        feedback = Fibonacci.Feedback()
        feedback.sequence = [0, 1]
        for i in range(1, goal_handle.request.order):
            feedback.sequence = [*feedback.sequence, int(feedback.sequence[i]) + int(feedback.sequence[i - 1])]
            goal_handle.publish_feedback(feedback)
            await asyncio.sleep(0)
        goal_handle.succeed()
        return Fibonacci.Result(sequence=feedback.sequence)

    feedbacks: list[list[int]] = []
    async with AsyncNode("fib_server", context=context) as server, AsyncNode("fib_client", context=context) as client_node:
        ActionServer(server, Fibonacci, "fibonacci", execute)
        client = ActionClient(client_node, Fibonacci, "fibonacci")
        async with asyncio.timeout(10):
            assert await client.wait_for_server()
            handle = await client.send_goal_async(
                Fibonacci.Goal(order=5), feedback_callback=lambda m: feedbacks.append(m.feedback.sequence.tolist())
            )
            assert handle.accepted
            response = await handle.get_result_async()
            assert response.result.sequence.tolist() == [0, 1, 1, 2, 3, 5]
            again = await client.send_goal(Fibonacci.Goal(order=3))
            assert again.result.sequence.tolist() == [0, 1, 1, 2]
    assert feedbacks[:1] == [[0, 1, 1]] and [0, 1, 1, 2, 3, 5] in feedbacks


PROGRAM = textwrap.dedent("""
    import asyncio
    import rclpy
    from rclpy.experimental import AsyncNode
    from std_msgs.msg import String

    async def main():
        done = asyncio.Event()
        async with AsyncNode('async_talker') as node:
            pub = node.create_publisher(String, 'chatter', 10)

            async def on_message(msg):
                node.get_logger().info('I heard: "%s"' % msg.data)
                done.set()

            node.create_subscription(String, 'chatter', on_message, 10)
            node.create_timer(0.05, lambda: pub.publish(String(data='Hello World')))
            await done.wait()

    with rclpy.init():
        asyncio.run(main())
""")


def test_an_async_node_program_runs_under_aiorobot_exec(tmp_path: Path):
    script = tmp_path / "async_talker.py"
    script.write_text(PROGRAM)
    program = Program(str(script))
    program.wait_for('I heard: "Hello World"')
    assert program.finish() == 0, program.output
    assert "Traceback" not in program.output, program.output
