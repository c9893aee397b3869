"""Services: calls, concurrency, errors, timeouts (wall and sim time), availability, groups."""

import asyncio

import pytest

from aiorobot import MutuallyExclusiveCallbackGroup, Node, ReentrantCallbackGroup, ServiceError, ServiceUnavailableError
from aiorobot.msgs.example_interfaces import AddTwoInts
from aiorobot.msgs.std_srvs import Trigger
from aiorobot.testing import settle


def add(request):
    return AddTwoInts.Response(sum=request.a + request.b)


@pytest.mark.parametrize("server_exec", ["main", "priority"])
async def test_call_returns_the_response(runtime, server_exec):
    server = runtime.add_node(Node("server"), executor=server_exec)
    server.create_service(AddTwoInts, "add", add)
    client = runtime.add_node(Node("client")).create_client(AddTwoInts, "/add")
    assert await client.wait_for_service(timeout_sec=10)
    response = await client.call(AddTwoInts.Request(a=2, b=3))
    assert response.sum == 5


async def test_concurrent_calls_are_matched_to_their_callers(runtime):
    server = runtime.add_node(Node("server"))

    async def slow_add(request):
        for _ in range(request.a % 5):  # finish out of order
            await asyncio.sleep(0)
        return AddTwoInts.Response(sum=request.a + request.b)

    server.create_service(AddTwoInts, "add", slow_add, callback_group=ReentrantCallbackGroup())
    client = runtime.add_node(Node("client")).create_client(AddTwoInts, "add")
    responses = await asyncio.gather(*[client.call(AddTwoInts.Request(a=i, b=1000)) for i in range(100)])
    assert [r.sum for r in responses] == [i + 1000 for i in range(100)]


async def test_handler_that_raises_answers_with_service_error(runtime, caplog):
    def broken(request):
        raise ValueError("disk full")

    runtime.add_node(Node("server")).create_service(Trigger, "save", broken)
    client = runtime.add_node(Node("client")).create_client(Trigger, "save")
    with pytest.raises(ServiceError, match=r"^service /save failed: ValueError: disk full$"):
        await client.call(Trigger.Request())
    assert "handler of service /save raised" in caplog.text


async def test_handler_returning_the_wrong_type_is_an_error(runtime):
    runtime.add_node(Node("server")).create_service(Trigger, "t", lambda req: "ok")
    client = runtime.add_node(Node("client")).create_client(Trigger, "t")
    with pytest.raises(ServiceError, match="returned str, expected std_srvs/srv/Trigger_Response"):
        await client.call(Trigger.Request())


async def test_timeout_raises_and_the_late_reply_is_dropped(runtime):
    release = asyncio.Event()
    server = runtime.add_node(Node("server"))
    answered = []

    async def stuck(request):
        await release.wait()
        answered.append(1)
        return Trigger.Response(success=True)

    server.create_service(Trigger, "stuck", stuck)
    client = runtime.add_node(Node("client")).create_client(Trigger, "stuck")
    with pytest.raises(TimeoutError, match="did not answer within 0.05 s"):
        await client.call(Trigger.Request(), timeout_sec=0.05)
    release.set()
    await settle(runtime)
    assert answered == [1] and client._pending == set()


async def test_timeout_follows_sim_time(sim_runtime, sim_clock):
    server = runtime_node = sim_runtime.add_node(Node("server"))
    server.create_service(Trigger, "never", lambda req: asyncio.Event().wait())
    client = sim_runtime.add_node(Node("client")).create_client(Trigger, "never")
    call = asyncio.ensure_future(client.call(Trigger.Request(), timeout_sec=0.05))
    await settle(sim_runtime)  # the call is under way; its timeout counts from sim time 0
    # Wall time passes, four times the timeout, and sim time does not: a wall-clock timeout
    # would fire here. (Stepping sim time in 10 ms steps past a busy server made this test
    # spend 10 s in settle's max_rounds.)
    await asyncio.sleep(0.2)
    assert not call.done()
    await sim_clock.advance(0.1, step_sec=0.05)
    with pytest.raises(TimeoutError):
        await call
    del runtime_node


async def test_missing_service_fails_fast(runtime):
    client = runtime.add_node(Node("client")).create_client(Trigger, "nobody")
    assert await client.wait_for_service(timeout_sec=0.01) is False
    with pytest.raises(ServiceUnavailableError, match="no server for service /nobody"):
        await client.call(Trigger.Request())


async def test_wait_for_service_wakes_when_the_server_appears(runtime):
    client = runtime.add_node(Node("client")).create_client(Trigger, "late")
    waiting = asyncio.ensure_future(client.wait_for_service(timeout_sec=30))
    await settle(runtime)
    assert not waiting.done()
    runtime.add_node(Node("server")).create_service(Trigger, "late", lambda r: Trigger.Response())
    assert await waiting is True


async def test_exclusive_group_serialises_handlers(runtime):
    server = runtime.add_node(Node("server"))
    active, peak = [], []

    async def handler(request):
        active.append(1)
        peak.append(len(active))
        await asyncio.sleep(0)
        active.pop()
        return Trigger.Response()

    server.create_service(Trigger, "t", handler, callback_group=MutuallyExclusiveCallbackGroup())
    client = runtime.add_node(Node("client")).create_client(Trigger, "t")
    await asyncio.gather(*[client.call(Trigger.Request()) for _ in range(10)])
    assert max(peak) == 1


async def test_wrong_request_type_is_rejected(runtime):
    client = runtime.add_node(Node("client")).create_client(Trigger, "t")
    with pytest.raises(TypeError, match="expects std_srvs/srv/Trigger_Request"):
        await client.call(AddTwoInts.Request())


async def test_graph_lists_services_with_servers_and_clients(runtime):
    runtime.add_node(Node("server", namespace="r")).create_service(Trigger, "reset", lambda r: Trigger.Response())
    runtime.add_node(Node("client")).create_client(Trigger, "/r/reset")
    [info] = [s for s in runtime.graph.services if s.name == "/r/reset"]  # not the parameter services
    assert (info.name, info.types, info.servers, info.clients) == (
        "/r/reset", ("std_srvs/srv/Trigger",), ("/r/server",), ("/client",)
    )


async def test_calls_in_flight_fail_when_the_server_node_is_removed(runtime):
    server = runtime.add_node(Node("server"))
    server.create_service(Trigger, "t", lambda r: asyncio.Event().wait())
    client = runtime.add_node(Node("client")).create_client(Trigger, "t")
    call = asyncio.ensure_future(client.call(Trigger.Request()))
    await settle(runtime)
    runtime.remove_node(server)
    with pytest.raises(ServiceError):
        await asyncio.wait_for(call, 30)
