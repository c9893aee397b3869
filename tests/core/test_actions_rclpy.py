"""rclpy's action shapes: handle_accepted_callback + goal_handle.execute() (queueing and preempting
servers as in ros2/examples), result_timeout expiry, and the *_async futures."""

import asyncio
from collections import deque

import pytest

from aiorobot import CancelResponse, Future, GoalStatus, Node, ReentrantCallbackGroup
from aiorobot.msgs.action_msgs import CancelGoal
from aiorobot.msgs.example_interfaces import Fibonacci
from aiorobot.testing import settle


class QueueServer(Node):
    """ros2/examples rclpy/actions/minimal_action_server/server_queue_goals.py, restated on asyncio."""

    def __init__(self):
        super().__init__("queue_server")
        self.queue = deque()
        self.current = None
        self.order = []
        self.gate = asyncio.Event()
        self.create_action_server(
            Fibonacci, "fibonacci", self.execute, handle_accepted_callback=self.on_accepted
        )

    def on_accepted(self, goal_handle):
        if self.current is not None:
            self.queue.append(goal_handle)  # a goal is executing: wait in line
        else:
            self.current = goal_handle
            goal_handle.execute()

    async def execute(self, goal_handle):
        try:
            self.order.append(goal_handle.request.order)
            await self.gate.wait()
            goal_handle.succeed()
            return Fibonacci.Result(sequence=[goal_handle.request.order])
        finally:
            self.current = self.queue.popleft() if self.queue else None
            if self.current is not None:
                self.current.execute()


async def _client(runtime, server):
    runtime.add_node(server)
    client = runtime.add_node(Node("client")).create_action_client(Fibonacci, "fibonacci")
    assert await client.wait_for_server(timeout_sec=10)
    return client


async def test_queueing_server_executes_goals_one_after_another(runtime):
    server = QueueServer()
    client = await _client(runtime, server)
    handles = [await client.send_goal(Fibonacci.Goal(order=n)) for n in (1, 2, 3)]
    await settle(runtime)
    assert all(h.accepted for h in handles)
    assert server.order == [1]  # only the first executes; the others wait ACCEPTED
    assert [h.status for h in handles] == [GoalStatus.EXECUTING, GoalStatus.ACCEPTED, GoalStatus.ACCEPTED]
    server.gate.set()
    results = [await h.result(timeout_sec=10) for h in handles]
    assert [list(r.sequence) for r in results] == [[1], [2], [3]]
    assert server.order == [1, 2, 3] and all(h.status is GoalStatus.SUCCEEDED for h in handles)


class SingleGoalServer(Node):
    """ros2/examples rclpy/actions/minimal_action_server/server_single_goal.py: a new goal preempts."""

    def __init__(self):
        super().__init__("single_server")
        self.goal_handle = None
        self.release = asyncio.Event()
        self.create_action_server(
            Fibonacci,
            "fibonacci",
            self.execute,
            handle_accepted_callback=self.on_accepted,
            cancel_callback=lambda gh: CancelResponse.ACCEPT,
        )

    def on_accepted(self, goal_handle):
        if self.goal_handle is not None and self.goal_handle.is_active:
            self.goal_handle.abort()  # preempt the running goal
        self.goal_handle = goal_handle
        goal_handle.execute()

    async def execute(self, goal_handle):
        while not self.release.is_set():
            if not goal_handle.is_active:
                return Fibonacci.Result()
            if goal_handle.is_cancel_requested:
                goal_handle.canceled()
                return Fibonacci.Result()
            await asyncio.sleep(0)
        if not goal_handle.is_active:
            return Fibonacci.Result()
        goal_handle.succeed()
        return Fibonacci.Result(sequence=[goal_handle.request.order])


async def test_a_new_goal_preempts_the_running_one(runtime):
    server = SingleGoalServer()
    client = await _client(runtime, server)
    first = await client.send_goal(Fibonacci.Goal(order=1))
    await settle(runtime)
    second = await client.send_goal(Fibonacci.Goal(order=2))
    assert list((await first.result(timeout_sec=10)).sequence) == []
    assert first.status is GoalStatus.ABORTED
    server.release.set()
    assert list((await second.result(timeout_sec=10)).sequence) == [2]
    assert second.status is GoalStatus.SUCCEEDED


async def test_cancel_deferred_goal(runtime):
    # rclpy rclpy/test/test_action_server.py::TestActionServer::test_cancel_defered_goal
    accepted = []

    def execute_callback(gh):
        assert gh.is_cancel_requested  # canceled before it executed
        gh.canceled()
        return Fibonacci.Result()

    node = runtime.add_node(Node("server"))
    node.create_action_server(
        Fibonacci,
        "fibonacci",
        execute_callback,
        callback_group=ReentrantCallbackGroup(),
        handle_accepted_callback=accepted.append,
        cancel_callback=lambda gh: CancelResponse.ACCEPT,
    )
    client = runtime.add_node(Node("client")).create_action_client(Fibonacci, "fibonacci")
    assert await client.wait_for_server(timeout_sec=10)
    handle = await client.send_goal(Fibonacci.Goal(order=3))
    await settle(runtime)
    assert handle.accepted and len(accepted) == 1
    server_handle = accepted[0]
    assert server_handle.status is GoalStatus.ACCEPTED
    response = await handle.cancel_goal_async()
    assert isinstance(response, CancelGoal.Response) and len(response.goals_canceling) == 1
    assert server_handle.status is GoalStatus.CANCELING
    server_handle.execute()
    result = await handle.get_result_async()
    assert result.status == GoalStatus.CANCELED and server_handle.status is GoalStatus.CANCELED
    with pytest.raises(RuntimeError, match="is finished; it cannot be executed"):
        server_handle.execute()


async def test_a_goal_aborted_while_queued_still_answers_get_result(runtime):
    accepted = []
    node = runtime.add_node(Node("server"))
    node.create_action_server(Fibonacci, "fibonacci", lambda gh: None, handle_accepted_callback=accepted.append)
    client = runtime.add_node(Node("client")).create_action_client(Fibonacci, "fibonacci")
    assert await client.wait_for_server(timeout_sec=10)
    handle = await client.send_goal(Fibonacci.Goal(order=3))
    await settle(runtime)
    accepted[0].abort()
    assert list((await handle.result(timeout_sec=10)).sequence) == []
    assert handle.status is GoalStatus.ABORTED


async def test_expire_goals_one(sim_runtime, sim_clock):
    # rclpy rclpy/test/test_action_server.py::TestActionServer::test_expire_goals_one (on sim time)
    def execute(gh):
        gh.succeed()
        return Fibonacci.Result(sequence=[1])

    node = sim_runtime.add_node(Node("server"))
    server = node.create_action_server(Fibonacci, "fibonacci", execute, result_timeout=1)
    client = sim_runtime.add_node(Node("client")).create_action_client(Fibonacci, "fibonacci")
    assert await client.wait_for_server(timeout_sec=10)
    handle = await client.send_goal(Fibonacci.Goal(order=1))
    assert list((await handle.result(timeout_sec=10)).sequence) == [1]
    assert len(server.goal_handles) == 1
    await sim_clock.advance(0.5)
    assert len(server.goal_handles) == 1
    await sim_clock.advance(1.6)  # 2.1 s after: forgotten
    assert len(server.goal_handles) == 0
    late = await client._get_result.call(Fibonacci.GetResult.Request(goal_id=handle.goal_id))
    assert late.status == GoalStatus.UNKNOWN


async def test_expire_goals_none(sim_runtime, sim_clock):
    # rclpy rclpy/test/test_action_server.py::TestActionServer::test_expire_goals_none
    node = sim_runtime.add_node(Node("server"))
    server = node.create_action_server(Fibonacci, "fibonacci", lambda gh: None, result_timeout=1)
    await sim_clock.advance(2.0)
    assert len(server.goal_handles) == 0


async def test_send_goal_async_and_get_result_async_futures(runtime):
    def execute(gh):
        gh.publish_feedback(Fibonacci.Feedback(sequence=[0, 1]))
        gh.succeed()
        return Fibonacci.Result(sequence=[0, 1, 1])

    runtime.add_node(Node("server")).create_action_server(Fibonacci, "fibonacci", execute)
    client = runtime.add_node(Node("client")).create_action_client(Fibonacci, "fibonacci")
    assert await client.wait_for_server(timeout_sec=10)
    goal_future = client.send_goal_async(Fibonacci.Goal(order=2))
    assert isinstance(goal_future, Future)
    goal_handle = await goal_future
    assert goal_future.done() and goal_future.result() is goal_handle and goal_handle.accepted
    result_future = goal_handle.get_result_async()
    got = []
    result_future.add_done_callback(lambda f: got.append((f.result().status, list(f.result().result.sequence))))
    response = await result_future
    await asyncio.sleep(0)
    assert response.status == GoalStatus.SUCCEEDED and got == [(GoalStatus.SUCCEEDED, [0, 1, 1])]
    with pytest.raises(TypeError, match="send_goal expects example_interfaces/action/Fibonacci_Goal"):
        client.send_goal_async(Fibonacci.Result())


def test_bad_action_server_arguments_are_refused():
    node = Node("n")
    with pytest.raises(ValueError, match=r"^result_timeout: expected a number of seconds >= 0, got -1$"):
        node.create_action_server(Fibonacci, "f", lambda gh: None, result_timeout=-1)
    with pytest.raises(TypeError, match="handle_accepted_callback must be callable"):
        node.create_action_server(Fibonacci, "f", lambda gh: None, handle_accepted_callback=3)


class MockServer(Node):
    """Accepts every goal, publishes feedback on demand, succeeds when told."""

    def __init__(self):
        super().__init__("mock_server")
        self.finish = asyncio.Event()
        self.handles = []
        self.server = self.create_action_server(
            Fibonacci, "fibonacci", self.execute, cancel_callback=lambda gh: CancelResponse.ACCEPT
        )

    async def execute(self, gh):
        self.handles.append(gh)
        await self.finish.wait()
        if gh.is_cancel_requested:
            gh.canceled()
        else:
            gh.succeed()
        return Fibonacci.Result(sequence=[1])


async def test_send_goal_multiple(runtime):
    # rclpy rclpy/test/test_action_client.py::TestActionClient::test_send_goal_multiple
    runtime.add_node(MockServer())
    ac = runtime.add_node(Node("client")).create_action_client(
        Fibonacci, "fibonacci", callback_group=ReentrantCallbackGroup()
    )
    assert await ac.wait_for_server(timeout_sec=2.0)
    futures = [ac.send_goal_async(Fibonacci.Goal()) for _ in range(3)]
    handles = [await f for f in futures]
    assert all(f.done() and f.result().accepted for f in futures)
    assert len({bytes(h.goal_id.uuid) for h in handles}) == 3


async def test_send_cancel_async(runtime):
    # rclpy rclpy/test/test_action_client.py::TestActionClient::test_send_cancel_async
    server = runtime.add_node(MockServer())
    ac = runtime.add_node(Node("client")).create_action_client(Fibonacci, "fibonacci")
    assert await ac.wait_for_server(timeout_sec=2.0)
    goal_future = ac.send_goal_async(Fibonacci.Goal())
    goal_handle = await goal_future
    cancel_future = goal_handle.cancel_goal_async()
    await cancel_future
    assert cancel_future.done()
    assert cancel_future.result().goals_canceling[0].goal_id == goal_handle.goal_id
    server.finish.set()
    assert (await goal_handle.get_result_async()).status == GoalStatus.CANCELED


async def test_get_result_async_and_goal_uuid(runtime):
    # rclpy rclpy/test/test_action_client.py::TestActionClient::test_get_result_async (with goal_uuid=, as
    # test_send_goal_async_with_feedback_after_goal passes it)
    import uuid

    from aiorobot.msgs.unique_identifier_msgs import UUID

    server = runtime.add_node(MockServer())
    server.finish.set()
    ac = runtime.add_node(Node("client")).create_action_client(Fibonacci, "fibonacci")
    assert await ac.wait_for_server(timeout_sec=2.0)
    goal_uuid = UUID(uuid=uuid.uuid4().bytes)
    goal_handle = await ac.send_goal_async(Fibonacci.Goal(), goal_uuid=goal_uuid)
    assert goal_handle.goal_id == goal_uuid
    result_future = goal_handle.get_result_async()
    result = await result_future
    assert result_future.done() and result.status == GoalStatus.SUCCEEDED and list(result.result.sequence) == [1]


async def test_feedback_for_another_goal_or_after_the_result_is_ignored(runtime):
    # rclpy test_action_client.py::test_send_goal_async_with_feedback_for_another_goal,
    # ::test_send_goal_async_with_feedback_after_goal_result_requested
    server = runtime.add_node(MockServer())
    ac = runtime.add_node(Node("client")).create_action_client(Fibonacci, "fibonacci")
    assert await ac.wait_for_server(timeout_sec=2.0)
    seen_a, seen_b = [], []
    a = await ac.send_goal_async(Fibonacci.Goal(order=1), feedback_callback=seen_a.append)
    b = await ac.send_goal_async(Fibonacci.Goal(order=2), feedback_callback=seen_b.append)
    await settle(runtime)
    server_a = next(h for h in server.handles if h.request.order == 1)
    server_a.publish_feedback(Fibonacci.Feedback(sequence=[7]))
    await settle(runtime)
    assert [list(m.feedback.sequence) for m in seen_a] == [[7]] and seen_b == []
    server.finish.set()
    await a.get_result_async()
    await b.get_result_async()
    # feedback published for goal a after its result: nobody hears it
    server.server._feedback_pub.publish(
        Fibonacci.FeedbackMessage(goal_id=a.goal_id, feedback=Fibonacci.Feedback(sequence=[8]))
    )
    await settle(runtime)
    assert len(seen_a) == 1


async def test_send_goal_async_without_a_server_fails_at_once(runtime):
    # rclpy test_action_client.py::test_send_goal_async_no_server (a deliberate difference: see the doc)
    from aiorobot import ServiceUnavailableError

    ac = runtime.add_node(Node("client")).create_action_client(Fibonacci, "not_fibonacci")
    future = ac.send_goal_async(Fibonacci.Goal())
    with pytest.raises(ServiceUnavailableError, match="no action server for /not_fibonacci"):
        await future


async def test_action_client_different_type_raises(runtime):
    # rclpy rclpy/test/test_action_client.py::TestActionClient::test_different_type_raises
    ac = runtime.add_node(Node("client")).create_action_client(Fibonacci, "fibonacci")
    with pytest.raises(TypeError):
        await ac.send_goal("different goal type")
    with pytest.raises(TypeError):
        ac.send_goal_async("different goal type")
