"""rclpy's service call shapes: cb(request, response), call_async futures, create_client(callback_group=...)."""

import asyncio
import threading

import pytest

from aiorobot import Future, MutuallyExclusiveCallbackGroup, Node, ServiceError, ServiceUnavailableError
from aiorobot._services import takes_response
from aiorobot.msgs.example_interfaces import AddTwoInts
from aiorobot.msgs.rcl_interfaces import GetParameters


async def test_concurrent_call_async_with_a_two_argument_handler(runtime):
    # rclpy rclpy/test/test_client.py::TestClient::test_concurrent_calls_to_service
    node = runtime.add_node(Node("node"))
    cli = node.create_client(GetParameters, "get/parameters")
    node.create_service(GetParameters, "get/parameters", lambda request, response: response)
    assert await cli.wait_for_service(timeout_sec=20)
    future1 = cli.call_async(GetParameters.Request())
    future2 = cli.call_async(GetParameters.Request())
    assert isinstance(future1, Future)
    assert isinstance(await future1, GetParameters.Response)
    assert await future2 is not None
    assert future1.done() and future1.result() is not None and future2.result() is not None


async def test_different_type_raises(runtime):
    # rclpy rclpy/test/test_client.py::TestClient::test_different_type_raises
    node = runtime.add_node(Node("node"))
    cli = node.create_client(GetParameters, "get/parameters")
    node.create_service(GetParameters, "get/parameters", lambda request, response: "different response type")
    with pytest.raises(TypeError):
        await cli.call("different request type")
    with pytest.raises(TypeError):
        cli.call_async("different request type")
    assert await cli.wait_for_service(timeout_sec=20)
    future = cli.call_async(GetParameters.Request())
    with pytest.raises(ServiceError, match="the handler returned str, expected rcl_interfaces/srv/GetParameters_Response"):
        await future
    assert isinstance(future.exception(), ServiceError)


async def test_the_two_argument_handler_gets_a_fresh_response_to_fill(runtime):
    server = runtime.add_node(Node("server"))
    seen = []

    def add(request, response):
        seen.append(response.sum)
        response.sum = request.a + request.b
        return response

    server.create_service(AddTwoInts, "add", add)
    cli = runtime.add_node(Node("client")).create_client(AddTwoInts, "add")
    assert (await cli.call(AddTwoInts.Request(a=2, b=3))).sum == 5
    assert (await cli.call(AddTwoInts.Request(a=4, b=3))).sum == 7
    assert seen == [0, 0]


async def test_async_two_argument_handlers_and_bound_methods(runtime):
    class Server(Node):
        def __init__(self):
            super().__init__("server")
            self.create_service(AddTwoInts, "add", self.add)

        async def add(self, request, response):
            await asyncio.sleep(0)
            response.sum = request.a + request.b
            return response

    runtime.add_node(Server())
    cli = runtime.add_node(Node("client")).create_client(AddTwoInts, "add")
    assert (await cli.call(AddTwoInts.Request(a=20, b=22))).sum == 42


def test_handler_arity_detection():
    def one(request):
        pass

    def with_default(request, context=None):
        pass

    def two(request, response):
        pass

    def star(*args):
        pass

    assert not takes_response(one) and not takes_response(with_default)
    assert takes_response(two) and takes_response(star) and takes_response(lambda a, b: b)


async def test_call_async_done_callback_runs_with_the_future(runtime):
    node = runtime.add_node(Node("node"))
    node.create_service(AddTwoInts, "add", lambda req: AddTwoInts.Response(sum=req.a + req.b))
    cli = node.create_client(AddTwoInts, "add", callback_group=MutuallyExclusiveCallbackGroup())
    done = asyncio.Event()
    got = []

    def on_done(fut):
        got.append(fut.result().sum)
        done.set()

    cli.call_async(AddTwoInts.Request(a=1, b=2)).add_done_callback(on_done)
    await asyncio.wait_for(done.wait(), 10)
    assert got == [3]


async def test_call_async_without_a_server_fails_at_once(runtime):
    cli = runtime.add_node(Node("node")).create_client(AddTwoInts, "nobody")
    with pytest.raises(ServiceUnavailableError, match="no server for service /nobody"):
        await cli.call_async(AddTwoInts.Request())


async def test_call_async_from_another_thread_runs_on_the_node_loop(runtime):
    node = runtime.add_node(Node("node"))
    node.create_service(AddTwoInts, "add", lambda req, res: AddTwoInts.Response(sum=req.a * req.b))
    cli = node.create_client(AddTwoInts, "add")
    box = []
    t = threading.Thread(target=lambda: box.append(cli.call_async(AddTwoInts.Request(a=6, b=7))))
    t.start()
    await asyncio.get_running_loop().run_in_executor(None, t.join)
    assert (await box[0]).sum == 42


async def test_cancelling_a_call_async_future_abandons_the_call(runtime):
    node = runtime.add_node(Node("node"))
    release = asyncio.Event()

    async def slow(req):
        await release.wait()
        return AddTwoInts.Response(sum=1)

    node.create_service(AddTwoInts, "slow", slow)
    cli = node.create_client(AddTwoInts, "slow")
    fut = cli.call_async(AddTwoInts.Request())
    await asyncio.sleep(0)
    assert fut.cancel()
    release.set()
    with pytest.raises(asyncio.CancelledError):
        await fut
    assert fut.cancelled() and fut.result() is None
