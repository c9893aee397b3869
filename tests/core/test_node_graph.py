"""Graph queries on Node, from rclpy's rclpy/test/test_node.py."""

import asyncio

import pytest

from aiorobot import InvalidNameError, Node, NodeNameNonExistentError
from aiorobot.msgs.example_interfaces import AddTwoInts, Fibonacci
from aiorobot.msgs.rcl_interfaces import GetParameters
from aiorobot.msgs.std_msgs import String

TEST_NODE = "my_node"
TEST_NAMESPACE = "/my_ns"


@pytest.fixture
def node(runtime):
    # Without its parameter services, so the graph holds only what each test creates.
    return runtime.add_node(Node(TEST_NODE, namespace=TEST_NAMESPACE, start_parameter_services=False))


def test_count_clients_services(node):
    # rclpy test_node.py::TestNodeAllowUndeclaredParameters::test_count_clients_services
    short, fq = "add_two_ints", f"{TEST_NAMESPACE}/add_two_ints"
    assert node.count_clients(fq) == 0 and node.count_services(fq) == 0
    node.create_client(GetParameters, short)
    assert node.count_clients(short) == 1 and node.count_clients(fq) == 1
    assert node.count_services(short) == 0 and node.count_services(fq) == 0
    node.create_service(GetParameters, short, lambda req: None)
    assert node.count_clients(short) == 1 and node.count_services(fq) == 1
    node.create_client(GetParameters, short)
    assert node.count_clients(fq) == 2 and node.count_services(short) == 1
    node.create_service(GetParameters, short, lambda req: None)
    assert node.count_clients(short) == 2 and node.count_services(fq) == 2
    with pytest.raises(TypeError):
        node.count_clients(1)
    with pytest.raises(TypeError):
        node.count_services(1)
    with pytest.raises(ValueError, match="invalid"):
        node.count_clients("42")
    with pytest.raises(InvalidNameError):
        node.count_services("42")


def test_count_publishers_subscribers_and_the_endpoint_counts(node):
    # rclpy test_node.py::TestNodeAllowUndeclaredParameters::test_count_publishers_subscribers
    short, fq = "chatter", f"{TEST_NAMESPACE}/chatter"
    assert node.count_publishers(fq) == 0 and node.count_subscribers(fq) == 0
    pub = node.create_publisher(String, short, 1)
    assert node.count_publishers(short) == 1 and pub.get_subscription_count() == 0
    sub = node.create_subscription(String, short, lambda msg: None, 1)
    assert node.count_subscribers(fq) == 1 and pub.get_subscription_count() == 1
    assert sub.get_publisher_count() == 1
    node.create_publisher(String, short, 1)
    assert sub.get_publisher_count() == 2
    with pytest.raises(TypeError):
        node.count_subscribers(1)
    with pytest.raises(ValueError, match="invalid"):
        node.count_publishers("42")


def test_publisher_count_skips_publishers_that_do_not_connect(node):
    from aiorobot import QoSProfile, ReliabilityPolicy

    sub = node.create_subscription(String, "t", lambda msg: None, QoSProfile(depth=1))  # reliable
    node.create_publisher(String, "t", QoSProfile(depth=1, reliability=ReliabilityPolicy.BEST_EFFORT))
    assert node.count_publishers("t") == 1 and sub.get_publisher_count() == 0


def test_node_names_and_namespaces(runtime, node):
    # rclpy test_node.py::TestNode::test_node_names, ::test_node_names_and_namespaces
    runtime.add_node(Node("root_node"))
    assert sorted(node.get_node_names()) == ["my_node", "root_node"]
    assert sorted(node.get_node_names_and_namespaces()) == [("my_node", "/my_ns"), ("root_node", "/")]
    assert sorted(node.get_fully_qualified_node_names()) == ["/my_ns/my_node", "/root_node"]
    # rclpy test_node.py::TestNode::test_node_names_and_namespaces_with_enclaves
    assert sorted(node.get_node_names_and_namespaces_with_enclaves()) == [
        ("my_node", "/my_ns", "/"),
        ("root_node", "/", "/"),
    ]


def test_service_and_client_names_and_types_by_node(runtime, node):
    # rclpy test_node.py::TestNode::test_service_names_and_types(_by_node), ::test_client_names_and_types_by_node
    other = runtime.add_node(Node("other", start_parameter_services=False))
    node.create_service(AddTwoInts, "add", lambda req: AddTwoInts.Response())
    other.create_client(AddTwoInts, "/my_ns/add")
    other.create_client(GetParameters, "/params")
    assert ("/my_ns/add", ["example_interfaces/srv/AddTwoInts"]) in node.get_service_names_and_types()
    assert ("/params", ["rcl_interfaces/srv/GetParameters"]) not in node.get_service_names_and_types()  # no server
    assert node.get_service_names_and_types_by_node(TEST_NODE, TEST_NAMESPACE) == [
        ("/my_ns/add", ["example_interfaces/srv/AddTwoInts"])
    ]
    assert node.get_service_names_and_types_by_node("other", "/") == []
    assert node.get_client_names_and_types_by_node("other", "/") == [
        ("/my_ns/add", ["example_interfaces/srv/AddTwoInts"]),
        ("/params", ["rcl_interfaces/srv/GetParameters"]),
    ]
    with pytest.raises(NodeNameNonExistentError, match="'/nowhere/ghost'"):
        node.get_service_names_and_types_by_node("ghost", "/nowhere")


def test_action_services_are_listed_as_services(node):
    node.create_action_server(Fibonacci, "fib", lambda gh: None)
    names = [n for n, _ in node.get_service_names_and_types()]
    assert "/my_ns/fib/_action/send_goal" in names and "/my_ns/fib/_action/get_result" in names


def test_publisher_and_subscriber_names_and_types_by_node(node):
    node.create_publisher(String, "out", 1)
    node.create_subscription(String, "in", lambda m: None, 1)
    assert node.get_publisher_names_and_types_by_node(TEST_NODE, TEST_NAMESPACE) == [
        ("/my_ns/out", ["std_msgs/msg/String"]),
        ("/parameter_events", ["rcl_interfaces/msg/ParameterEvent"]),  # every node has it, as in rclpy
        ("/rosout", ["rcl_interfaces/msg/Log"]),  # this one too
    ]
    assert node.get_subscriber_names_and_types_by_node(TEST_NODE, TEST_NAMESPACE) == [
        ("/my_ns/in", ["std_msgs/msg/String"])
    ]


async def test_wait_for_node(runtime, node):
    # rclpy test_node.py::TestNode::test_wait_for_node
    waiting = asyncio.ensure_future(node.wait_for_node("/my_ns/waiting_for_this_node", 3.0))
    await asyncio.sleep(0)
    runtime.add_node(Node("waiting_for_this_node", namespace=TEST_NAMESPACE))
    assert await waiting is True
    assert await node.wait_for_node("my_node", 0.0) is False  # root namespace: /my_node does not exist


async def test_wait_for_node_timeout(sim_runtime, sim_clock):
    # rclpy test_node.py::TestNode::test_wait_for_node_timeout (on sim time)
    node = sim_runtime.add_node(Node("n"))
    waiting = asyncio.ensure_future(node.wait_for_node("node_does_not_exist", 0.1))
    await sim_clock.advance(0.2)
    assert await waiting is False
