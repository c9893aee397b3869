"""Fibonacci: an action server and client with feedback and cancel, ported from the ROS 2 tutorial.

    python examples/fibonacci_action.py 10            # run a goal to the end
    python examples/fibonacci_action.py 40 --cancel   # cancel it after three feedbacks
"""

from __future__ import annotations

import argparse

import aiorobot
from aiorobot import CancelResponse, GoalResponse, Node, Runtime
from aiorobot.msgs.example_interfaces import Fibonacci


class FibonacciActionServer(Node):
    def __init__(self, **kw):
        super().__init__("fibonacci_action_server", **kw)
        self.declare_parameter("step_sec", 0.05, description="pause between two feedbacks")
        self.create_action_server(
            Fibonacci,
            "fibonacci",
            self.execute,
            goal_callback=self.on_goal,
            cancel_callback=lambda goal_handle: CancelResponse.ACCEPT,
        )

    def on_goal(self, goal: Fibonacci.Goal) -> GoalResponse:
        return GoalResponse.ACCEPT if goal.order >= 0 else GoalResponse.REJECT

    async def execute(self, goal_handle) -> Fibonacci.Result:
        self.get_logger().info("executing goal...")
        sequence = [0, 1]
        step = self.get_parameter("step_sec").value
        for i in range(1, goal_handle.request.order):
            if goal_handle.is_cancel_requested:
                goal_handle.canceled()
                self.get_logger().info("goal canceled")
                return Fibonacci.Result(sequence=sequence)
            sequence.append(sequence[i] + sequence[i - 1])
            goal_handle.publish_feedback(Fibonacci.Feedback(sequence=sequence))
            await self.get_clock().sleep_for(step)
        goal_handle.succeed()
        return Fibonacci.Result(sequence=sequence)


class FibonacciActionClient(Node):
    def __init__(self, **kw):
        super().__init__("fibonacci_action_client", **kw)
        self.client = self.create_action_client(Fibonacci, "fibonacci")

    async def run_goal(self, order: int, cancel_after: int | None = None):
        """Send a goal, print its feedback, cancel after ``cancel_after`` feedbacks; return (status, result)."""
        if not await self.client.wait_for_server(timeout_sec=5.0):
            raise RuntimeError("action server fibonacci not available")
        handle = await self.client.send_goal(Fibonacci.Goal(order=order))
        if not handle.accepted:
            self.get_logger().info("goal rejected")
            return handle.status, None
        count = 0
        async for feedback in handle.feedback():
            count += 1
            print(f"feedback: {list(map(int, feedback.sequence))}")
            if cancel_after is not None and count == cancel_after:
                print(f"cancel accepted: {await handle.cancel()}")
                break
        result = await handle.result()
        print(f"result ({handle.status.name}): {list(map(int, result.sequence))}")
        return handle.status, result


async def main(order: int, cancel: bool) -> None:
    async with Runtime() as rt:
        rt.add_node(FibonacciActionServer())
        client = rt.add_node(FibonacciActionClient())
        await client.run_goal(order, cancel_after=3 if cancel else None)


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("order", type=int, nargs="?", default=10)
    parser.add_argument("--cancel", action="store_true")
    args = parser.parse_args()
    aiorobot.run(main(args.order, args.cancel))
