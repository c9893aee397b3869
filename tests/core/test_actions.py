"""Actions: accept/reject, feedback, results with status, cancel accepted/refused, aborts, several goals."""

import asyncio
import uuid

import numpy as np
import pytest

from aiorobot import CancelResponse, GoalResponse, GoalStatus, Node, ServiceUnavailableError
from aiorobot.msgs.example_interfaces import Fibonacci


class Server(Node):
    def __init__(self, *, cancel=CancelResponse.ACCEPT, fail_at=None):
        super().__init__("fib_server")
        self.step = asyncio.Event()
        self.fail_at = fail_at
        self.cancel = cancel
        self.create_action_server(
            Fibonacci, "fibonacci", self.execute, goal_callback=self.on_goal, cancel_callback=lambda gh: self.cancel
        )

    def on_goal(self, goal):
        return GoalResponse.REJECT if goal.order < 0 else GoalResponse.ACCEPT

    async def execute(self, gh):
        seq = [0, 1]
        for i in range(1, gh.request.order):
            if gh.is_cancel_requested:
                gh.canceled()
                return Fibonacci.Result(sequence=seq)
            if i == self.fail_at:
                raise RuntimeError("motor stalled")
            seq.append(seq[i] + seq[i - 1])
            gh.publish_feedback(Fibonacci.Feedback(sequence=seq))
            await asyncio.sleep(0)
        gh.succeed()
        return Fibonacci.Result(sequence=seq)


async def _client(runtime, server, executor="main"):
    runtime.add_node(server, executor=executor)
    client = runtime.add_node(Node("fib_client")).create_action_client(Fibonacci, "fibonacci")
    assert await client.wait_for_server(timeout_sec=10)
    return client


@pytest.mark.parametrize("executor", ["main", "priority"])
async def test_goal_succeeds_with_feedback_and_result(runtime, executor):
    client = await _client(runtime, Server(), executor)
    seen = []
    handle = await client.send_goal(Fibonacci.Goal(order=6), feedback_callback=lambda m: seen.append(m))
    assert handle.accepted
    iterated = [list(fb.sequence) async for fb in handle.feedback()]
    result = await handle.result()
    assert handle.status is GoalStatus.SUCCEEDED
    assert list(result.sequence) == [0, 1, 1, 2, 3, 5, 8]
    assert iterated[-1] == [0, 1, 1, 2, 3, 5, 8] and len(iterated) == 5
    await asyncio.sleep(0)
    assert [list(m.feedback.sequence) for m in seen] == iterated
    assert all(bytes(m.goal_id.uuid) == bytes(handle.goal_id.uuid) for m in seen)


async def test_goal_ids_are_random_uuids(runtime):
    client = await _client(runtime, Server())
    a = await client.send_goal(Fibonacci.Goal(order=1))
    b = await client.send_goal(Fibonacci.Goal(order=1))
    assert a.goal_id.uuid.dtype == np.uint8 and a.goal_id.uuid.shape == (16,)
    assert uuid.UUID(a.goal_id_str).version == 4 and a.goal_id_str != b.goal_id_str
    await asyncio.gather(a.result(), b.result())


async def test_rejected_goal(runtime):
    client = await _client(runtime, Server())
    handle = await client.send_goal(Fibonacci.Goal(order=-1))
    assert not handle.accepted


async def test_cancel_accepted_ends_canceled(runtime):
    server = Server()
    client = await _client(runtime, server)
    handle = await client.send_goal(Fibonacci.Goal(order=10_000))
    async for _ in handle.feedback():
        break
    assert await handle.cancel() is True
    result = await handle.result()
    assert handle.status is GoalStatus.CANCELED and len(result.sequence) < 10_000


async def test_cancel_refused_goal_runs_to_success(runtime):
    client = await _client(runtime, Server(cancel=CancelResponse.REJECT))
    handle = await client.send_goal(Fibonacci.Goal(order=20))
    assert await handle.cancel() is False
    await handle.result()
    assert handle.status is GoalStatus.SUCCEEDED


async def test_execute_that_raises_aborts_that_goal_only(runtime, caplog):
    client = await _client(runtime, Server(fail_at=3))
    bad = await client.send_goal(Fibonacci.Goal(order=10))
    good = await client.send_goal(Fibonacci.Goal(order=2))
    await asyncio.gather(bad.result(), good.result())
    assert bad.status is GoalStatus.ABORTED and good.status is GoalStatus.SUCCEEDED
    assert "motor stalled" in caplog.text


async def test_execute_that_sets_no_state_is_aborted_with_a_warning(runtime, caplog):
    node = runtime.add_node(Node("server"))
    node.create_action_server(Fibonacci, "f", lambda gh: Fibonacci.Result())
    client = runtime.add_node(Node("c")).create_action_client(Fibonacci, "f")
    await client.wait_for_server(10)
    handle = await client.send_goal(Fibonacci.Goal(order=1))
    await handle.result()
    assert handle.status is GoalStatus.ABORTED and "state not set" in caplog.text


async def test_several_goals_run_concurrently(runtime):
    client = await _client(runtime, Server())
    handles = await asyncio.gather(*[client.send_goal(Fibonacci.Goal(order=n)) for n in range(2, 12)])
    results = await asyncio.gather(*[h.result() for h in handles])
    assert [len(r.sequence) for r in results] == [n + 1 for n in range(2, 12)]
    assert all(h.status is GoalStatus.SUCCEEDED for h in handles)


async def test_send_goal_without_server_fails_fast(runtime):
    client = runtime.add_node(Node("c")).create_action_client(Fibonacci, "nobody")
    assert await client.wait_for_server(timeout_sec=0.01) is False
    with pytest.raises(ServiceUnavailableError, match="no action server for /nobody"):
        await client.send_goal(Fibonacci.Goal(order=1))


async def test_graph_lists_the_action(runtime):
    await _client(runtime, Server())
    [info] = runtime.graph.actions
    assert info.name == "/fibonacci" and info.types == ("example_interfaces/action/Fibonacci",)
    assert info.servers == ("/fib_server",) and info.clients == ("/fib_client",)
