"""Native aiorobot nodes that the tests add to an rclpy program's graph (``aiorobot exec --node``)."""

from __future__ import annotations

import asyncio

import aiorobot
from aiorobot.msgs.example_interfaces import AddTwoInts, Fibonacci
from aiorobot.msgs.std_msgs import String


class Listener(aiorobot.Node):
    def __init__(self) -> None:
        super().__init__("native_listener")
        self.create_subscription(String, "/topic", self.on_msg, 10)
        self.create_subscription(String, "/chatter", self.on_msg, 10)

    async def on_msg(self, msg: String) -> None:
        print(f"native heard: {msg.data}", flush=True)


class Talker(aiorobot.Node):
    def __init__(self) -> None:
        super().__init__("native_talker")
        self.topic = self.create_publisher(String, "/topic", 10)
        self.chatter = self.create_publisher(String, "/chatter", 10)
        self.count = 0
        self.create_timer(0.1, self.tick)

    async def tick(self) -> None:
        msg = String(data=f"native {self.count}")
        self.count += 1
        self.topic.publish(msg)
        self.chatter.publish(msg)


class AddTwoIntsServer(aiorobot.Node):
    def __init__(self) -> None:
        super().__init__("native_add_two_ints_server")
        self.create_service(AddTwoInts, "/add_two_ints", self.add)

    async def add(self, request: AddTwoInts.Request) -> AddTwoInts.Response:
        print(f"native server: {request.a} + {request.b}", flush=True)
        return AddTwoInts.Response(sum=request.a + request.b)


class AddTwoIntsClient(aiorobot.Node):
    def __init__(self) -> None:
        super().__init__("native_add_two_ints_client")
        self.client = self.create_client(AddTwoInts, "/add_two_ints")

    async def on_start(self) -> None:
        await self.client.wait_for_service()
        response = await self.client.call(AddTwoInts.Request(a=2, b=3))
        print(f"native client got: {response.sum}", flush=True)


class FibonacciClient(aiorobot.Node):
    def __init__(self) -> None:
        super().__init__("native_fibonacci_client")
        self.client = self.create_action_client(Fibonacci, "/fibonacci")

    async def on_start(self) -> None:
        await self.client.wait_for_server()
        handle = await self.client.send_goal(Fibonacci.Goal(order=3))
        result = await handle.result()
        print(f"native action result: {list(result.sequence)} {handle.status.name}", flush=True)


class FibonacciServer(aiorobot.Node):
    def __init__(self) -> None:
        super().__init__("native_fibonacci_server")
        self.create_action_server(Fibonacci, "/fibonacci", self.execute)

    async def execute(self, goal_handle: object) -> Fibonacci.Result:
        seq = [0, 1]
        for i in range(1, goal_handle.request.order):  # type: ignore[attr-defined]
            seq.append(seq[i] + seq[i - 1])
            goal_handle.publish_feedback(Fibonacci.Feedback(sequence=seq))  # type: ignore[attr-defined]
        goal_handle.succeed()  # type: ignore[attr-defined]
        return Fibonacci.Result(sequence=seq)


class SlowFibonacciServer(aiorobot.Node):
    """As examples_rclpy_minimal_action_server/server.py: one step per period, cancel accepted."""

    def __init__(self) -> None:
        super().__init__("native_slow_fibonacci_server")
        self.create_action_server(Fibonacci, "/fibonacci", self.execute, cancel_callback=lambda _h: True)

    async def execute(self, goal_handle: object) -> Fibonacci.Result:
        seq = [0, 1]
        for i in range(1, goal_handle.request.order):  # type: ignore[attr-defined]
            if goal_handle.is_cancel_requested:  # type: ignore[attr-defined]
                goal_handle.canceled()  # type: ignore[attr-defined]
                return Fibonacci.Result(sequence=seq)
            seq.append(seq[i] + seq[i - 1])
            goal_handle.publish_feedback(Fibonacci.Feedback(sequence=seq))  # type: ignore[attr-defined]
            await asyncio.sleep(0.5)  # the upstream server's pace (1 s), halved
        goal_handle.succeed()  # type: ignore[attr-defined]
        return Fibonacci.Result(sequence=seq)
