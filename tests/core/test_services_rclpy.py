"""rclpy's service call shapes: cb(request, response), call_async futures, create_client(callback_group=...)."""

import asyncio
import threading

import pytest

from aiorobot import Future, MutuallyExclusiveCallbackGroup, Node, ServiceError, ServiceUnavailableError
from aiorobot._core._services import takes_response
from aiorobot.msgs.example_interfaces import AddTwoInts
from aiorobot.msgs.rcl_interfaces import GetParameters
from aiorobot.msgs.std_srvs import Trigger


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


@pytest.mark.parametrize(
    "service_name, namespace, expected",
    [
        ("service", None, "/service"),
        ("example/service", None, "/example/service"),
        ("service", "ns", "/ns/service"),
        ("example/service", "ns", "/ns/example/service"),
        ("example/service", "my/ns", "/my/ns/example/service"),
        ("example/service", "/my/ns", "/my/ns/example/service"),
        ("/service", "ns", "/service"),
        ("/example/service", "ns", "/example/service"),
    ],
)
def test_get_service_name(service_name, namespace, expected):
    # rclpy rclpy/test/test_service.py::test_get_service_name (keyword names as rclpy's)
    node = Node("node_name", namespace=namespace or "")
    srv = node.create_service(srv_type=Trigger, srv_name=service_name, callback=lambda _: None)
    cli = node.create_client(srv_type=Trigger, srv_name=service_name)
    assert srv.service_name == expected and cli.service_name == expected
    srv.destroy()


@pytest.mark.parametrize(
    "service_name, namespace, remap, expected",
    [
        ("service", None, {"service": "new_service"}, "/new_service"),
        ("service", "ns", {"service": "new_service"}, "/ns/new_service"),
        ("service", "ns", {"service": "example/new_service"}, "/ns/example/new_service"),
        ("example/service", "ns", {"example/service": "new_service"}, "/ns/new_service"),
    ],
)
def test_get_service_name_after_remapping(service_name, namespace, remap, expected):
    # rclpy rclpy/test/test_service.py::test_get_service_name_after_remapping
    node = Node("node_name", namespace=namespace or "", remappings=remap)
    srv = node.create_service(srv_type=Trigger, srv_name=service_name, callback=lambda _: None)
    assert srv.service_name == expected


def test_service_context_manager():
    # rclpy rclpy/test/test_service.py::test_service_context_manager
    node = Node("ctx_mgr_test")
    with node.create_service(srv_type=Trigger, srv_name="empty_service", callback=lambda _: None) as srv:
        assert srv.service_name == "/empty_service"
    assert srv not in node._services
    with node.create_client(Trigger, "empty_service") as cli:
        assert cli.service_name == "/empty_service"
    assert cli.destroyed


@pytest.mark.parametrize("factory", ["client", "service"])
def test_create_client_and_service_validate_the_name(factory):
    # rclpy rclpy/test/test_node.py::TestNode::test_create_client, ::test_create_service
    node = Node("n")

    def make(name):
        if factory == "client":
            return node.create_client(GetParameters, name)
        return node.create_service(GetParameters, name, lambda req: None)

    make("get/parameters")
    with pytest.raises(ValueError, match=r"character '\?' is not allowed"):
        make("get/parameters?")
    with pytest.raises(ValueError, match="must not start with a digit"):
        make("/get/42parameters")
    with pytest.raises(ValueError, match="unknown substitution"):
        make("foo/{bad_sub}")


async def test_remove_pending_request_abandons_the_call(runtime):
    # rclpy client.py: Client.remove_pending_request(future)
    node = runtime.add_node(Node("node"))
    release = asyncio.Event()

    async def slow(req):
        await release.wait()
        return AddTwoInts.Response(sum=1)

    node.create_service(AddTwoInts, "slow", slow)
    cli = node.create_client(AddTwoInts, "slow")
    fut = cli.call_async(AddTwoInts.Request())
    await asyncio.sleep(0)
    cli.remove_pending_request(fut)
    release.set()
    assert fut.cancelled() and fut.result() is None
