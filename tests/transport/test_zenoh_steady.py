"""A steady stream the receiver keeps up with loses nothing between two processes (issue 27)."""

from __future__ import annotations

from aiorobot import Node, QoSProfile, ReliabilityPolicy, Runtime
from aiorobot.msgs.geometry_msgs import Twist
from aiorobot.transport import ZenohTransport

from ._helpers import spawn, wait_until

COUNT = 2000

DRIVER = """
from aiorobot.msgs.geometry_msgs import Twist, Vector3
async def main(rt):
    node = Node("driver")
    rt.add_node(node)
    pub = node.create_publisher(Twist, "/cmd_vel", QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE))
    say("ready")
    reader = await stdin_lines()
    loop = asyncio.get_running_loop()
    while (await reader.readline()).decode().strip() == "ping":  # until the route is up: one marked message
        pub.publish(Twist(linear=Vector3(x=-1.0)))
        say("pinged")
    start = loop.time()
    for i in range(%d):  # 1 kHz on the loop's clock: a steady stream, not a burst
        pub.publish(Twist(linear=Vector3(x=float(i))))
        await asyncio.sleep(max(0.0, start + (i + 1) / 1000 - loop.time()))
    say("done", rt.transport.statistics().sent)
    await reader.readline()
""" % COUNT


async def test_a_steady_1khz_twist_stream_at_depth_10_arrives_whole_and_in_order(router_port: int) -> None:
    child = await spawn(DRIVER, router_port)
    try:
        await child.expect("ready")
        transport = ZenohTransport(connect=[f"tcp/127.0.0.1:{router_port}"])
        async with Runtime(transport=transport, handle_signals=False) as rt:
            node = rt.add_node(Node("base"))
            got: list[int] = []
            qos = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE)
            sub = node.create_subscription(Twist, "/cmd_vel", lambda m: got.append(int(m.linear.x)), qos)
            await wait_until(lambda: len(rt.graph.publishers_of("/cmd_vel")) == 1)
            for _ in range(100):  # the route is up once one message came through
                child.send("ping")
                await child.expect("pinged")
                try:
                    await wait_until(lambda: bool(got), timeout_sec=0.5)
                    break
                except TimeoutError:
                    continue
            assert got and set(got) == {-1}
            child.send("go")
            line = await child.expect("done")
            assert int(line.split()[1]) >= COUNT
            stream = lambda: [x for x in got if x >= 0]  # noqa: E731 - (a late ping is no part of it)
            try:
                await wait_until(lambda: len(stream()) >= COUNT)
            except TimeoutError:
                raise AssertionError(f"{len(stream())} {rt.transport.statistics()} {sub.dropped} {sorted(set(range(COUNT)) - set(stream()))[:30]}") from None
            assert stream() == list(range(COUNT)), f"missing: {sorted(set(range(COUNT)) - set(stream()))[:20]}"
            assert sub.dropped == 0
            assert rt.transport.statistics().dropped == 0
            child.send("bye")
    finally:
        await child.stop()
