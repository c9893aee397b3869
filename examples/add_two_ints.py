"""AddTwoInts: a service server and a client, ported from the ROS 2 tutorial.

    python examples/add_two_ints.py 2 3
"""

from __future__ import annotations

import sys

import aiorobot
from aiorobot import Node, Runtime
from aiorobot.msgs.example_interfaces import AddTwoInts


class AddTwoIntsServer(Node):
    def __init__(self, **kw):
        super().__init__("add_two_ints_server", **kw)
        self.create_service(AddTwoInts, "add_two_ints", self.add_two_ints)

    async def add_two_ints(self, request: AddTwoInts.Request) -> AddTwoInts.Response:
        self.get_logger().info(f"incoming request a: {request.a} b: {request.b}")
        return AddTwoInts.Response(sum=request.a + request.b)


class AddTwoIntsClient(Node):
    def __init__(self, **kw):
        super().__init__("add_two_ints_client", **kw)
        self.client = self.create_client(AddTwoInts, "add_two_ints")

    async def add(self, a: int, b: int) -> int:
        if not await self.client.wait_for_service(timeout_sec=5.0):
            raise RuntimeError("service add_two_ints not available")
        response = await self.client.call(AddTwoInts.Request(a=a, b=b), timeout_sec=5.0)
        return response.sum


async def main(a: int, b: int) -> int:
    async with Runtime() as rt:
        rt.add_node(AddTwoIntsServer())
        client = rt.add_node(AddTwoIntsClient())
        total = await client.add(a, b)
    print(f"Result of add_two_ints: for {a} + {b} = {total}")
    return total


if __name__ == "__main__":
    args = sys.argv[1:] or ["2", "3"]
    if len(args) != 2 or not all(x.lstrip("-").isdigit() for x in args):
        sys.exit("usage: add_two_ints.py A B   (two integers)")
    aiorobot.run(main(int(args[0]), int(args[1])))
