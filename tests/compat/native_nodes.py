"""Native aiorobot nodes that the tests add to an rclpy program's graph (``aiorobot exec --node``)."""

from __future__ import annotations

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


# -- tf (tests/compat/test_tf2_compat.py) ---------------------------------------------------


def _fmt(values: tuple[float, ...]) -> str:
    return "(" + ", ".join(f"{v:.3f}" for v in values) + ")"


class TfEcho(aiorobot.Node):
    """Prints every transform on /tf and /tf_static: topic, parent, child, translation, rotation."""

    def __init__(self) -> None:
        from aiorobot.msgs.tf2_msgs import TFMessage
        from aiorobot.tf._broadcasters import DYNAMIC_QOS, STATIC_QOS

        super().__init__("native_tf_echo")
        self.create_subscription(TFMessage, "/tf", lambda m: self.echo("/tf", m), DYNAMIC_QOS)
        self.create_subscription(TFMessage, "/tf_static", lambda m: self.echo("/tf_static", m), STATIC_QOS)

    def echo(self, topic: str, msg: object) -> None:
        for t in msg.transforms:  # type: ignore[attr-defined]
            tr, ro = t.transform.translation, t.transform.rotation
            print(
                f"native tf echo {topic} {t.header.frame_id}->{t.child_frame_id} "
                f"t={_fmt((tr.x, tr.y, tr.z))} q={_fmt((ro.x, ro.y, ro.z, ro.w))}",
                flush=True,
            )


class _TfLookup(aiorobot.Node):
    """A native aiorobot.tf Buffer + TransformListener printing one lookup every 0.2 s."""

    target = ""
    source = ""

    def __init__(self) -> None:
        from aiorobot.tf import Buffer, TransformListener

        super().__init__(f"native_tf_lookup_{self.source}")
        self.buffer = Buffer()
        self.listener = TransformListener(self.buffer, self)
        self.create_timer(0.2, self.tick)

    async def tick(self) -> None:
        from aiorobot import Time

        if not self.buffer.can_transform(self.target, self.source, Time()):
            return
        t = self.buffer.lookup_transform(self.target, self.source, Time())
        tr, ro = t.transform.translation, t.transform.rotation
        print(
            f"native lookup {self.target}<-{self.source} t={_fmt((tr.x, tr.y, tr.z))} "
            f"q={_fmt((ro.x, ro.y, ro.z, ro.w))}",
            flush=True,
        )


class CarrotLookup(_TfLookup):
    target, source = "turtle1", "carrot1"


class StaticTurtleLookup(_TfLookup):
    target, source = "world", "mystaticturtle"


class OdomBroadcaster(aiorobot.Node):
    """Sends odom -> base_link on /tf at 20 Hz: 1 m along x, turned 90 degrees about z, stamped now."""

    def __init__(self) -> None:
        from aiorobot.tf import TransformBroadcaster

        super().__init__("native_odom_broadcaster")
        self.broadcaster = TransformBroadcaster(self)
        self.create_timer(0.05, self.tick)

    async def tick(self) -> None:
        from aiorobot.msgs.geometry_msgs import TransformStamped

        t = TransformStamped()
        t.header.stamp = self.get_clock().now().to_msg()
        t.header.frame_id = "odom"
        t.child_frame_id = "base_link"
        t.transform.translation.x = 1.0
        t.transform.rotation.z = 0.7071067811865476
        t.transform.rotation.w = 0.7071067811865476
        self.broadcaster.send_transform(t)
