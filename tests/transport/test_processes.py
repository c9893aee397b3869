"""Real child processes on loopback: pub/sub per QoS combination, transient local, services, actions."""

from __future__ import annotations

import asyncio
import logging

import pytest

from aiorobot import DurabilityPolicy, Node, QoSProfile, ReliabilityPolicy
from aiorobot.msgs.example_interfaces import AddTwoInts, Fibonacci
from aiorobot.msgs.geometry_msgs import Twist, Vector3

from ._helpers import peer_runtime, spawn, wait_until

R, BE = ReliabilityPolicy.RELIABLE, ReliabilityPolicy.BEST_EFFORT
V, TL = DurabilityPolicy.VOLATILE, DurabilityPolicy.TRANSIENT_LOCAL
COMBOS = [(R, V), (R, TL), (BE, V), (BE, TL)]

TALKER = """
from aiorobot.msgs.geometry_msgs import Twist, Vector3
COMBOS = [(1, 2), (1, 1), (2, 2), (2, 1)]
async def main(rt):
    node = Node("talker")
    rt.add_node(node)
    pubs = [node.create_publisher(Twist, f"/t{i}", QoSProfile(reliability=r, durability=d, depth=3))
            for i, (r, d) in enumerate(COMBOS)]
    for pub in pubs:
        pub.publish(Twist(linear=Vector3(x=-1.0)))   # before anyone listens: only transient local keeps it
    say("ready")
    reader = await stdin_lines()
    while line := (await reader.readline()).decode().strip():
        if line == "wait-matched":  # every publisher sees a subscription of the listener's
            while not all(pub.get_subscription_count() for pub in pubs):
                await asyncio.sleep(0.01)
            say("matched")
            continue
        for pub in pubs:
            pub.publish(Twist(linear=Vector3(x=float(line))))
        say("sent", line)
"""


async def test_pub_sub_across_processes_for_each_qos_combination(router_port: int) -> None:
    child = await spawn(TALKER, router_port)
    try:
        await child.expect("ready")
        async with peer_runtime(router_port) as rt:
            node = rt.add_node(Node("listener"))
            got: dict[int, list[float]] = {i: [] for i in range(4)}
            for i, (rel, dur) in enumerate(COMBOS):
                node.create_subscription(
                    Twist, f"/t{i}", lambda m, i=i: got[i].append(m.linear.x), QoSProfile(reliability=rel, durability=dur, depth=3)
                )
            # the transient-local topics replay what was published before this process existed
            await wait_until(lambda: got[1] == [-1.0] and got[3] == [-1.0])
            await wait_until(lambda: all(len(rt.graph.publishers_of(f"/t{i}")) == 1 for i in range(4)))
            assert rt.graph.publishers_of("/t0")[0].node == "/talker"
            assert rt.graph.publishers_of("/t1")[0].qos.durability is TL
            # a volatile message published before the subscription's route reached the talker is lost,
            # as with rmw_zenoh: the talker waits until it counts this process's subscriptions
            child.send("wait-matched")
            await child.expect("matched")
            n = 0
            while not all(len(v) >= 2 for v in got.values()):
                n += 1
                child.send(str(n))
                await child.expect("sent")  # each round trip through the child paces the next
                assert n < 1000
            assert got[0][0] == 1.0 and got[2][0] >= 1.0
            assert got[0] == sorted(got[0]) and got[1][1:] == sorted(got[1][1:])
    finally:
        await child.stop()


async def test_qos_mismatch_across_processes_is_reported_and_not_delivered(
    router_port: int, caplog: pytest.LogCaptureFixture
) -> None:
    child = await spawn(TALKER, router_port)
    try:
        await child.expect("ready")
        async with peer_runtime(router_port) as rt:
            node = rt.add_node(Node("strict"))
            got: list[float] = []
            with caplog.at_level(logging.WARNING, logger="aiorobot.runtime"):
                # /t2 is best effort: a reliable subscription must not connect
                node.create_subscription(Twist, "/t2", lambda m: got.append(m.linear.x), QoSProfile(depth=3))
                await wait_until(lambda: bool(rt.graph.incompatible_qos))
            bad = rt.graph.incompatible_qos[0]
            assert bad.topic == "/t2" and bad.publisher_node == "/talker" and "BEST_EFFORT" in bad.reason
            assert any("incompatible QoS on /t2" in r.message and "/talker" in r.message for r in caplog.records)
            child.send("5")
            await child.expect("sent")
            # a compatible subscription on another topic proves the message did travel
            other: list[float] = []
            node.create_subscription(Twist, "/t0", lambda m: other.append(m.linear.x), 3)
            await wait_until(lambda: len(rt.graph.publishers_of("/t0")) == 1)
            while not other:
                child.send("6")
                await child.expect("sent")
            assert got == []
    finally:
        await child.stop()


SERVER = """
from aiorobot.msgs.example_interfaces import AddTwoInts, Fibonacci
class Server(Node):
    def __init__(self):
        super().__init__("server", namespace="/robot")
        self.create_service(AddTwoInts, "add", self.add)
        self.create_action_server(Fibonacci, "fib", self.fib)
    def add(self, req):
        if req.a < 0:
            raise ValueError("negative")
        return AddTwoInts.Response(sum=req.a + req.b)
    async def fib(self, handle):
        seq = [0, 1]
        for _ in range(handle.request.order - 1):
            seq.append(seq[-1] + seq[-2])
            handle.publish_feedback(Fibonacci.Feedback(sequence=list(seq)))
            await asyncio.sleep(0.01)
        handle.succeed()
        return Fibonacci.Result(sequence=seq)
async def main(rt):
    rt.add_node(Server())
    say("ready")
    await rt.spin()
"""


async def test_services_and_actions_across_processes(router_port: int) -> None:
    child = await spawn(SERVER, router_port)
    try:
        await child.expect("ready")
        async with peer_runtime(router_port) as rt:
            node = rt.add_node(Node("caller"))
            client = node.create_client(AddTwoInts, "/robot/add")
            assert await client.wait_for_service(timeout_sec=20)
            response = await client.call(AddTwoInts.Request(a=40, b=2), timeout_sec=10)
            assert response.sum == 42
            from aiorobot import ServiceError

            with pytest.raises(ServiceError, match="negative"):
                await client.call(AddTwoInts.Request(a=-1, b=2), timeout_sec=10)
            calls = await asyncio.gather(*(client.call(AddTwoInts.Request(a=i, b=i), timeout_sec=10) for i in range(20)))
            assert [c.sum for c in calls] == [2 * i for i in range(20)]

            action = node.create_action_client(Fibonacci, "/robot/fib")
            assert await action.wait_for_server(timeout_sec=20)
            await wait_until(lambda: len(rt.graph.subscriptions_of("/robot/fib/_action/feedback")) >= 1)
            handle = await action.send_goal(Fibonacci.Goal(order=6))
            assert handle.accepted
            feedback = [list(fb.sequence) async for fb in handle.feedback()]
            result = await handle.result(timeout_sec=20)
            assert list(result.sequence) == [0, 1, 1, 2, 3, 5, 8]
            assert feedback and feedback[-1] == [0, 1, 1, 2, 3, 5, 8]
            graph = rt.graph
            assert any(a.name == "/robot/fib" and "/robot/server" in a.servers for a in graph.actions)
            assert any(s.name == "/robot/add" and s.servers == ("/robot/server",) for s in graph.services)
    finally:
        await child.stop()
