"""The graph CLI (``aiorobot topic|node|service|graph|router``) against a running graph in another process."""

from __future__ import annotations

import asyncio
import sys

import pytest

from tests.transport._helpers import free_port, open_router, spawn

GRAPH = """
from aiorobot.msgs.std_msgs import String
from aiorobot.msgs.geometry_msgs import Twist
from aiorobot.msgs.example_interfaces import AddTwoInts, Fibonacci
async def fib(handle):
    seq = [0, 1]
    for _ in range(handle.request.order - 1):
        seq.append(seq[-1] + seq[-2])
        handle.publish_feedback(Fibonacci.Feedback(sequence=list(seq)))
    handle.succeed()
    return Fibonacci.Result(sequence=seq)
async def main(rt):
    node = rt.add_node(Node("talker", namespace="/robot"))
    node.create_action_server(Fibonacci, "/fib", fib)
    pub = node.create_publisher(String, "/chatter", 10)
    node.create_subscription(Twist, "/cmd_vel", lambda m: say("cmd_vel", m.linear.x), 10)
    node.create_service(AddTwoInts, "/add", lambda r: AddTwoInts.Response(sum=r.a + r.b))
    say("ready")
    n = 0
    while True:
        n += 1
        pub.publish(String(data=f"hello {n}"))
        await asyncio.sleep(0.02)
"""


@pytest.fixture
async def graph_port():  # type: ignore[no-untyped-def]
    port = free_port()
    router = open_router(port)
    child = await spawn(GRAPH, port)
    try:
        await child.expect("ready")
        yield port, child
    finally:
        await child.stop()
        router.close()


async def cli(port: int, *argv: str) -> tuple[int, str, str]:
    proc = await asyncio.create_subprocess_exec(
        sys.executable, "-m", "aiorobot.cli", *argv, "--connect", f"tcp/127.0.0.1:{port}",
        stdout=asyncio.subprocess.PIPE, stderr=asyncio.subprocess.PIPE,
    )
    out, err = await asyncio.wait_for(proc.communicate(), 30)
    return proc.returncode or 0, out.decode(), err.decode()


async def test_topic_node_service_and_graph_commands_see_the_other_process(graph_port, tmp_path) -> None:  # type: ignore[no-untyped-def]
    port, child = graph_port
    code, out, err = await cli(port, "topic", "list", "-t")
    assert code == 0, err
    assert "/chatter [std_msgs/msg/String]" in out.splitlines() and "/cmd_vel [geometry_msgs/msg/Twist]" in out.splitlines()

    code, out, err = await cli(port, "topic", "echo", "/chatter", "--once")
    assert code == 0, err
    assert out.startswith("data: hello ") and out.rstrip().endswith("---")

    code, out, err = await cli(port, "topic", "info", "/chatter", "--verbose")
    assert code == 0, err
    assert "Publisher count: 1" in out and "Node namespace: /robot" in out

    code, out, err = await cli(port, "node", "list")
    assert code == 0, err
    assert out.split() == ["/robot/talker"]

    code, out, err = await cli(port, "node", "info", "/robot/talker")
    assert code == 0, err
    assert "/chatter: std_msgs/msg/String" in out and "/add: example_interfaces/srv/AddTwoInts" in out

    code, out, err = await cli(port, "service", "call", "/add", "example_interfaces/srv/AddTwoInts", "{a: 40, b: 2}")
    assert code == 0, err
    assert "response:\nsum: 42" in out

    code, out, err = await cli(port, "topic", "pub", "/cmd_vel", "geometry_msgs/msg/Twist", "{linear: {x: 0.5}}", "--once")
    assert code == 0, err
    assert (await child.expect("cmd_vel")) == "cmd_vel 0.5"

    code, out, err = await cli(port, "action", "list", "-t")
    assert code == 0, err
    assert out.splitlines() == ["/fib [example_interfaces/action/Fibonacci]"]

    code, out, err = await cli(port, "action", "send_goal", "/fib", "example_interfaces/action/Fibonacci", "{order: 5}")
    assert code == 0, err
    assert "Result:\nsequence:\n- 0\n- 1\n- 1\n- 2\n- 3\n- 5\n" in out and "status: SUCCEEDED" in out

    code, out, err = await cli(port, "graph", "--dot")
    assert code == 0, err
    assert '"/robot/talker" -> "/chatter";' in out

    page = tmp_path / "graph.html"
    code, out, err = await cli(port, "graph", "--html", str(page))
    assert code == 0, err
    html = page.read_text()
    assert html.startswith("<!DOCTYPE html>") and '<g class="node" data-name="/robot/talker">' in html
    assert 'data-from="/robot/talker" data-to="/chatter"' in html and 'data-from="/cmd_vel" data-to="/robot/talker"' in html


async def test_topic_pub_with_yaml_that_does_not_fit_the_type_names_the_field(graph_port) -> None:  # type: ignore[no-untyped-def]
    port, _child = graph_port
    code, out, err = await cli(port, "topic", "pub", "/cmd_vel", "geometry_msgs/msg/Twist", "{linear: {q: 1}}")
    assert code == 1
    assert err.strip().splitlines() == [
        "aiorobot topic pub: error: geometry_msgs/msg/Twist.linear.q: geometry_msgs/msg/Vector3 has no field 'q'; "
        "its fields are x, y, z"
    ]
