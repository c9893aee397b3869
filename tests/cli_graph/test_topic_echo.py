"""``aiorobot topic echo NAME [TYPE]`` as ``ros2 topic echo``: the optional type, and a topic not
published yet is waited for with one warning instead of ending the command (issue 25)."""

from __future__ import annotations

import asyncio
import sys

import pytest

from tests.transport._helpers import free_port, open_router, spawn

pytestmark = pytest.mark.timeout(90)

LATE_PUBLISHER = """
from aiorobot.msgs.std_msgs import String
async def main(rt):
    node = rt.add_node(Node("late", namespace="/robot"))
    lines = await stdin_lines()
    say("ready")
    await lines.readline()
    pub = node.create_publisher(String, "/late", 10)
    say("publishing")
    while True:
        pub.publish(String(data="finally"))
        await asyncio.sleep(0.02)
"""


@pytest.fixture
async def late_graph():  # type: ignore[no-untyped-def]
    port = free_port()
    router = open_router(port)
    child = await spawn(LATE_PUBLISHER, port)
    try:
        await child.expect("ready")
        yield port, child
    finally:
        await child.stop()
        router.close()


async def start_cli(port: int, *argv: str) -> asyncio.subprocess.Process:
    return await asyncio.create_subprocess_exec(
        sys.executable, "-m", "aiorobot.cli", *argv, "--connect", f"tcp/127.0.0.1:{port}",
        stdout=asyncio.subprocess.PIPE, stderr=asyncio.subprocess.PIPE,
    )


@pytest.mark.parametrize("type_args", [(), ("std_msgs/msg/String",)], ids=["type-from-graph", "type-given"])
async def test_echo_waits_for_a_topic_that_is_not_published_yet(late_graph, type_args) -> None:  # type: ignore[no-untyped-def]
    port, child = late_graph
    echo = await start_cli(port, "topic", "echo", "/late", *type_args, "--once")
    assert echo.stderr is not None
    warning = await asyncio.wait_for(echo.stderr.readline(), 30)
    assert warning.decode().startswith("WARNING: topic [/late] does not appear to be published yet; waiting for it")
    child.send("go")
    await child.expect("publishing")
    out, err = await asyncio.wait_for(echo.communicate(), 30)
    assert echo.returncode == 0, err.decode()
    assert out.decode() == "data: finally\n---\n"


async def test_echo_with_a_type_that_is_not_a_message_type_is_one_line(late_graph) -> None:  # type: ignore[no-untyped-def]
    port, _child = late_graph
    echo = await start_cli(port, "topic", "echo", "/late", "std_msgs/msg/Strin", "--once")
    out, err = await asyncio.wait_for(echo.communicate(), 30)
    assert echo.returncode == 1
    assert err.decode().strip().splitlines() == [
        "aiorobot topic echo: error: type: expected a known message type such as geometry_msgs/msg/Twist, "
        "found 'std_msgs/msg/Strin'"
    ]
