"""clientPublish: what the Foxglove app publishes (teleop, "Publish pose", "Publish pose
estimate") reaches the graph; an unknown topic, a bad schema or bad bytes get an error status
and nothing is published."""

from __future__ import annotations

import asyncio
import math
from collections.abc import Callable
from pathlib import Path

import cv2
import numpy as np
import pytest

from aiorobot import Node, Runtime
from aiorobot.foxglove import FoxgloveBridge
from aiorobot.msgs import serialize
from aiorobot.msgs.geometry_msgs import Point, Pose, PoseStamped, PoseWithCovarianceStamped, Twist, TwistStamped, Vector3

pytest.importorskip("websockets")
from foxglove_wsclient import FoxgloveClient  # noqa: E402

ERROR = 2


class Base(Node):
    """Keeps every Twist it receives on /cmd_vel."""

    def __init__(self) -> None:
        super().__init__("base")
        self.received: list[Twist] = []
        self.create_subscription(Twist, "/cmd_vel", self.received.append, 100)


async def _poll(rt: Runtime, condition: Callable[[], object], what: str, bound: int = 2000) -> None:
    for _ in range(bound):
        if condition():
            return
        await rt.settle()
        await asyncio.sleep(0.01)
    raise AssertionError(f"never happened: {what}")


async def test_teleop_twist_at_20_hz_arrives_whole_and_in_order() -> None:
    async with Runtime(handle_signals=False) as rt:
        base = rt.add_node(Base())
        bridge = rt.add_node(FoxgloveBridge(port=0))
        async with FoxgloveClient(bridge.bound_port) as client:
            info = await client.wait_op("serverInfo")
            assert "clientPublish" in info["capabilities"]
            await client.advertise(1, "/cmd_vel", "geometry_msgs/msg/Twist")
            for i in range(20):  # the teleop panel's rate
                await client.publish(1, serialize(Twist(linear=Vector3(x=0.1 * i), angular=Vector3(z=-0.5))))
                await asyncio.sleep(0.05)
            await _poll(rt, lambda: len(base.received) >= 20, "20 Twists on /cmd_vel")
        assert [round(m.linear.x, 6) for m in base.received] == [round(0.1 * i, 6) for i in range(20)]
        assert {m.angular.z for m in base.received} == {-0.5}
        assert not client.statuses(ERROR)
        stats = bridge.statistics()
        assert (stats.client_published, stats.client_refused) == (20, 0)


async def test_unknown_topic_gets_an_error_status_and_nothing_is_published() -> None:
    async with Runtime(handle_signals=False) as rt:
        bridge = rt.add_node(FoxgloveBridge(port=0))
        async with FoxgloveClient(bridge.bound_port) as client:
            await client.wait_op("serverInfo")
            await client.advertise(3, "/nowhere", "geometry_msgs/msg/Twist")
            await client.publish(3, serialize(Twist()))
            status = await client.wait_op("status", lambda d: "/nowhere" in d["message"])
        assert status["level"] == ERROR
        assert "unknown topic" in status["message"] and "nothing published" in status["message"]
        assert rt.graph.publishers_of("/nowhere") == ()
        assert bridge.statistics().client_published == 0


async def test_bad_schema_and_bad_bytes_are_refused_and_a_good_channel_still_publishes() -> None:
    async with Runtime(handle_signals=False) as rt:
        base = rt.add_node(Base())
        bridge = rt.add_node(FoxgloveBridge(port=0))
        async with FoxgloveClient(bridge.bound_port) as client:
            await client.wait_op("serverInfo")
            await client.advertise(4, "/cmd_vel", "geometry_msgs/msg/TwistStamped")
            await client.publish(4, serialize(TwistStamped()))
            schema = await client.wait_op("status", lambda d: "bad schema" in d["message"])
            await client.advertise(5, "/cmd_vel", "geometry_msgs/msg/Twist", encoding="json")
            encoding = await client.wait_op("status", lambda d: "encoding" in d["message"])
            await client.advertise(6, "/cmd_vel", "geometry_msgs/Twist")  # the ROS 1 spelling names the same type
            await client.publish(6, b"\x00\x01")
            garbage = await client.wait_op("status", lambda d: "bad message" in d["message"])
            await client.publish(6, serialize(Twist(linear=Vector3(x=2.0))))
            await _poll(rt, lambda: base.received, "the good Twist")
        assert "geometry_msgs/msg/Twist" in schema["message"] and "TwistStamped" in schema["message"]
        assert "expected message encoding 'cdr', found 'json'" in encoding["message"]
        assert "do not decode as geometry_msgs/msg/Twist" in garbage["message"]
        assert all(s["level"] == ERROR for s in (schema, encoding, garbage))
        assert [m.linear.x for m in base.received] == [2.0]  # only the good one went out
        assert bridge.statistics().client_refused == 2


def _room(tmp: Path) -> str:
    img = np.full((80, 80), 254, np.uint8)
    img[:2, :] = img[-2:, :] = img[:, :2] = img[:, -2:] = 0
    cv2.imwrite(str(tmp / "room.pgm"), img)
    (tmp / "room.yaml").write_text("image: room.pgm\nresolution: 0.05\norigin: [-2.0, -2.0, 0.0]\noccupied_thresh: 0.65\nfree_thresh: 0.196\nnegate: 0\n")
    return str(tmp / "room.yaml")


async def test_a_pose_published_on_goal_pose_becomes_a_navigate_to_pose_goal(tmp_path: Path) -> None:
    from aiorobot.msgs.geometry_msgs import TransformStamped
    from aiorobot.msgs.nav_msgs import Path as PathMsg
    from aiorobot.nav import MapServer, NavigationServer
    from aiorobot.tf import StaticTransformBroadcaster

    async with Runtime(handle_signals=False) as rt:
        rt.add_node(MapServer(yaml_filename=_room(tmp_path)))
        server = rt.add_node(NavigationServer())
        robot = rt.add_node(Node("robot"))
        t = TransformStamped()
        t.header.frame_id, t.child_frame_id = "map", "base_link"
        t.transform.rotation.w = 1.0
        StaticTransformBroadcaster(robot).send_transform(t)
        plans: list[PathMsg] = []
        robot.create_subscription(PathMsg, "/plan", plans.append, 10)
        bridge = rt.add_node(FoxgloveBridge(port=0))
        await _poll(rt, lambda: server.costmap is not None, "the map at the navigation server")
        async with FoxgloveClient(bridge.bound_port) as client:
            await client.wait_op("serverInfo")
            await client.advertise(1, "/goal_pose", "geometry_msgs/msg/PoseStamped")
            goal = PoseStamped(pose=Pose(position=Point(x=1.0, y=0.5)))
            goal.header.frame_id = "map"
            goal.pose.orientation.w = 1.0
            await client.publish(1, serialize(goal))
            await _poll(rt, lambda: plans, "a plan toward the clicked goal")
            assert not client.statuses(ERROR)
        end = plans[0].poses[-1].pose.position
        assert math.hypot(end.x - 1.0, end.y - 0.5) < 0.1
        assert server.statistics().navigating


async def test_a_pose_estimate_published_on_initialpose_reaches_amcl(tmp_path: Path) -> None:
    from aiorobot.nav import AmclNode, MapServer

    async with Runtime(handle_signals=False) as rt:
        rt.add_node(MapServer(yaml_filename=_room(tmp_path)))
        amcl = rt.add_node(AmclNode())
        bridge = rt.add_node(FoxgloveBridge(port=0))
        await _poll(rt, lambda: amcl.filter is not None, "the map at AMCL")
        assert not amcl.filter.initialized
        async with FoxgloveClient(bridge.bound_port) as client:
            await client.wait_op("serverInfo")
            await client.advertise(2, "/initialpose", "geometry_msgs/msg/PoseWithCovarianceStamped")
            estimate = PoseWithCovarianceStamped()
            estimate.header.frame_id = "map"
            estimate.pose.pose.position.x, estimate.pose.pose.position.y = 0.5, -0.3
            estimate.pose.pose.orientation.w = 1.0
            cov = [0.0] * 36
            cov[0] = cov[7] = cov[35] = 1e-4
            estimate.pose.covariance = cov
            await client.publish(2, serialize(estimate))
            await _poll(rt, lambda: amcl.filter.initialized, "AMCL's initial pose")
        x, y, _ = amcl.filter.pose
        assert math.hypot(x - 0.5, y + 0.3) < 0.05
