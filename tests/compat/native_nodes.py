"""Native aiorobot nodes that the tests add to an rclpy program's graph (``aiorobot exec --node``)."""

from __future__ import annotations

import asyncio
import logging

import aiorobot
from aiorobot.msgs.example_interfaces import AddTwoInts, Fibonacci
from aiorobot.msgs.lifecycle_msgs import ChangeState, GetState, Transition, TransitionEvent
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
class _LogWatch(logging.Handler):
    """Sets an event on the driver's loop when another node logs a line containing ``needle``."""

    def __init__(self, loop: asyncio.AbstractEventLoop) -> None:
        super().__init__()
        self.loop = loop
        self.waiting: list[tuple[str, asyncio.Event]] = []

    def emit(self, record: logging.LogRecord) -> None:
        text = record.getMessage()
        for needle, event in list(self.waiting):
            if needle in text:
                self.loop.call_soon_threadsafe(event.set)

    async def wait_for(self, needle: str) -> None:
        event = asyncio.Event()
        self.waiting.append((needle, event))
        try:
            async with asyncio.timeout(DRIVER_WAIT_SEC):
                await event.wait()
        finally:
            self.waiting.remove((needle, event))


#: generous: the machine is shared; each step normally takes at most one talker period (1 s)
DRIVER_WAIT_SEC = 15.0


class LifecycleTalkerDriver(aiorobot.Node):
    """Walks lifecycle_py's ``lc_talker`` through its states by its lifecycle services, as the
    demo's README does with ``ros2 lifecycle set``, and listens on /lifecycle_chatter."""

    def __init__(self) -> None:
        super().__init__("native_lifecycle_driver")
        self.change_state = self.create_client(ChangeState, "/lc_talker/change_state")
        self.get_state = self.create_client(GetState, "/lc_talker/get_state")
        self.create_subscription(String, "/lifecycle_chatter", self.on_msg, 10)
        # as the demo's lc_listener
        self.create_subscription(TransitionEvent, "/lc_talker/transition_event", self.on_event, 10)
        self.heard = 0
        self.heard_changed = asyncio.Event()
        self.finalized = asyncio.Event()

    async def on_msg(self, msg: String) -> None:
        self.heard += 1
        self.heard_changed.set()
        print(f"native heard: {msg.data}", flush=True)

    async def on_event(self, event: TransitionEvent) -> None:
        print(f"native notify callback: Transition from state {event.start_state.label} to "
              f"{event.goal_state.label}", flush=True)
        if event.goal_state.label == "finalized":
            self.finalized.set()

    async def state(self) -> str:
        response = await self.get_state.call(GetState.Request(), DRIVER_WAIT_SEC)
        return response.current_state.label

    async def set(self, label: str) -> None:
        response = await self.change_state.call(
            ChangeState.Request(transition=Transition(label=label)), DRIVER_WAIT_SEC
        )
        print(f"driver: {label} -> success {response.success}, state {await self.state()}", flush=True)

    async def on_start(self) -> None:
        watch = _LogWatch(asyncio.get_running_loop())
        talker_log = logging.getLogger("aiorobot.node.lc_talker")
        talker_log.addHandler(watch)
        try:
            await self.drive(watch)
        except TimeoutError:
            print("driver: timed out", flush=True)
        finally:
            talker_log.removeHandler(watch)

    async def drive(self, watch: _LogWatch) -> None:
        async with asyncio.timeout(DRIVER_WAIT_SEC):
            await self.change_state.wait_for_service()
            await self.get_state.wait_for_service()
        print(f"driver: state {await self.state()}", flush=True)
        await self.set("activate")  # not offered by 'unconfigured': refused
        await self.set("configure")
        await self.set("activate")
        async with asyncio.timeout(DRIVER_WAIT_SEC):
            while self.heard < 2:
                self.heard_changed.clear()
                await self.heard_changed.wait()
        await self.set("deactivate")
        # Between two ticks of the talker's timer while inactive nothing may arrive (a message
        # published before the deactivation has long been delivered by the first).
        await watch.wait_for("Lifecycle publisher is inactive")
        heard = self.heard
        await watch.wait_for("Lifecycle publisher is inactive")
        print(f"driver: heard {self.heard - heard} while inactive", flush=True)
        await self.set("cleanup")
        await self.set("shutdown")
        async with asyncio.timeout(DRIVER_WAIT_SEC):
            await self.finalized.wait()
        print("driver: done", flush=True)
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


class CloudListener(aiorobot.Node):
    """Reads pointcloud_publisher.py's /test_cloud back with aiorobot.msgs.point_cloud2."""

    def __init__(self) -> None:
        super().__init__("native_cloud_listener")
        from aiorobot.msgs.sensor_msgs import PointCloud2

        self.create_subscription(PointCloud2, "/test_cloud", self.on_cloud, 10)

    async def on_cloud(self, msg: object) -> None:
        from aiorobot.msgs import point_cloud2

        xyz = point_cloud2.read_points_numpy(msg, field_names=("x", "y", "z"))
        print(
            f"native cloud: {msg.width}x{msg.height} in {msg.header.frame_id}, "  # type: ignore[attr-defined]
            f"x {xyz[:, 0].min():.1f}..{xyz[:, 0].max():.1f}, |z| <= {abs(xyz[:, 2]).max():.2f}",
            flush=True,
        )


class ParameterBlackboard(aiorobot.Node):
    """demo_nodes_cpp's parameter_blackboard: takes any parameter (undeclared ones allowed)."""

    def __init__(self) -> None:
        super().__init__(
            "parameter_blackboard", allow_undeclared_parameters=True,
            automatically_declare_parameters_from_overrides=True,
        )


class SetParam1Driver(aiorobot.Node):
    """As the README's ``ros2 service call /set_parameters_callback/set_parameters`` with param1 = 1.0,
    then reads param1 and param2 back through get_parameters."""

    def __init__(self) -> None:
        super().__init__("native_param_driver")
        from aiorobot.msgs.rcl_interfaces import GetParameters, SetParameters

        self.set = self.create_client(SetParameters, "/set_parameters_callback/set_parameters")
        self.get = self.create_client(GetParameters, "/set_parameters_callback/get_parameters")

    async def on_start(self) -> None:
        from aiorobot.msgs import rcl_interfaces as ri

        await self.set.wait_for_service()
        await self.get.wait_for_service()
        value = ri.ParameterValue(type=3, double_value=1.0)
        response = await self.set.call(ri.SetParameters.Request(parameters=[ri.Parameter(name="param1", value=value)]))
        print(f"native set param1: {[(r.successful, r.reason) for r in response.results]}", flush=True)
        got = await self.get.call(ri.GetParameters.Request(names=["param1", "param2"]))
        print(f"native got: param1={got.values[0].double_value} param2={got.values[1].double_value}", flush=True)


class BestEffortListener(aiorobot.Node):
    """Hears /chatter with best-effort QoS (qos_profile_sensor_data): any talker_qos connects."""

    def __init__(self) -> None:
        super().__init__("native_best_effort_listener")
        self.create_subscription(String, "/chatter", self.on_msg, aiorobot.qos_profile_sensor_data)

    async def on_msg(self, msg: String) -> None:
        print(f"native heard: {msg.data}", flush=True)


class ServiceEventEcho(aiorobot.Node):
    """``ros2 topic echo /add_two_ints/_service_event``: one line per introspection event."""

    def __init__(self) -> None:
        super().__init__("native_service_event_echo")
        self.create_subscription(AddTwoInts.Event, "/add_two_ints/_service_event", self.on_event, 10)

    async def on_event(self, event: AddTwoInts.Event) -> None:
        info = event.info
        request = [(r.a, r.b) for r in event.request]
        response = [r.sum for r in event.response]
        print(
            f"native event: type={info.event_type} seq={info.sequence_number} gid={bytes(info.client_gid).hex()} "
            f"request={request} response={response}",
            flush=True,
        )
