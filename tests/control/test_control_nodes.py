"""Base controller nodes with the runtime: watchdog, shutdown stop, odometry from wheel feedback."""

from __future__ import annotations

import math

import numpy as np
import pytest

try:
    from aiorobot import Node, Runtime
except ImportError:  # the runtime is not exported yet
    pytest.skip("needs aiorobot.Node and aiorobot.Runtime", allow_module_level=True)

from aiorobot.msgs.geometry_msgs import Twist  # noqa: E402
from aiorobot.msgs.nav_msgs import Odometry  # noqa: E402
from aiorobot.msgs.sensor_msgs import JointState  # noqa: E402

from aiorobot.control import DiffDriveController, MecanumController  # noqa: E402
from _helpers import wait_until  # noqa: E402




class Probe(Node):
    """Publishes /cmd_vel and /joint_states on demand, records /wheel_commands and /odom."""

    def __init__(self, **kw):
        super().__init__("probe", **kw)
        self.cmd_pub = self.create_publisher(Twist, "/cmd_vel", 10)
        self.joint_pub = self.create_publisher(JointState, "/joint_states", 10)
        self.wheel_commands: list[np.ndarray] = []
        self.wheel_names: list[list[str]] = []
        self.odom: list[Odometry] = []
        self.streaming: Twist | None = None
        self.create_subscription(JointState, "/wheel_commands", self.on_wheels, 100)
        self.create_subscription(Odometry, "/odom", self.odom.append, 100)
        self.create_timer(0.02, self.tick)

    def on_wheels(self, msg):
        self.wheel_commands.append(np.asarray(msg.velocity, dtype=float).copy())
        self.wheel_names.append(list(msg.name))

    def tick(self):
        if self.streaming is not None:
            self.cmd_pub.publish(self.streaming)


def twist(vx=0.0, vy=0.0, wz=0.0):
    msg = Twist()
    msg.linear.x, msg.linear.y, msg.angular.z = vx, vy, wz
    return msg


@pytest.mark.parametrize("executor", ["main", "priority"])
async def test_watchdog_zeroes_wheels_when_cmd_vel_stops(executor, caplog):
    async with Runtime() as rt:
        controller = DiffDriveController(
            parameter_overrides={"cmd_timeout_sec": 0.2, "max_accel_x": 100.0, "wheel_radius": 0.1}
        )
        probe = Probe()
        rt.add_node(controller, executor=executor)
        rt.add_node(probe)
        probe.streaming = twist(vx=0.5)
        await wait_until(lambda: probe.wheel_commands and np.all(probe.wheel_commands[-1] > 4.0))
        assert probe.wheel_names[-1] == ["left_wheel_joint", "right_wheel_joint"]
        probe.streaming = None  # the command source goes quiet
        moving = len(probe.wheel_commands)
        await wait_until(lambda: len(probe.wheel_commands) > moving and not np.any(probe.wheel_commands[-1]))
        assert controller.watchdog_trips == 1
        # it stays stopped
        count = len(probe.wheel_commands)
        await wait_until(lambda: len(probe.wheel_commands) > count + 5)
        assert not np.any(np.stack(probe.wheel_commands[count:]))
        warnings = [r for r in caplog.records if "no /cmd_vel for more than cmd_timeout_sec=0.2 s" in r.getMessage()]
        assert len(warnings) == 1  # throttled, not one per tick
        assert warnings[0].levelname == "WARNING"


async def test_commands_keep_flowing_while_cmd_vel_arrives():
    async with Runtime() as rt:
        controller = MecanumController(parameter_overrides={"cmd_timeout_sec": 0.2, "max_accel_y": 100.0})
        probe = Probe()
        rt.add_node(controller, executor="priority")
        rt.add_node(probe)
        probe.streaming = twist(vy=0.2)
        await wait_until(lambda: len(probe.wheel_commands) > 40)
        last = probe.wheel_commands[-1]
        # pure sideways motion: fl and rr backward, fr and rl forward
        assert last[0] < 0 and last[1] > 0 and last[2] > 0 and last[3] < 0
        assert controller.watchdog_trips == 0


async def test_shutdown_publishes_a_zero_wheel_command_last():
    probe = Probe()
    async with Runtime() as rt:
        controller = MecanumController(parameter_overrides={"cmd_timeout_sec": 5.0, "max_accel_x": 100.0})
        rt.add_node(controller, executor="priority")
        rt.add_node(probe)
        probe.streaming = twist(vx=0.4)
        await wait_until(lambda: probe.wheel_commands and np.all(probe.wheel_commands[-1] > 5.0))
    assert not np.any(probe.wheel_commands[-1])
    assert len(probe.wheel_commands[-1]) == 4


async def test_limits_are_applied_before_the_wheels():
    async with Runtime() as rt:
        controller = DiffDriveController(
            parameter_overrides={"max_linear_x": 0.3, "max_accel_x": 1000.0, "wheel_radius": 0.1, "max_wheel_speed": 100.0}
        )
        probe = Probe()
        rt.add_node(controller, executor="priority")
        rt.add_node(probe)
        probe.streaming = twist(vx=5.0)
        await wait_until(lambda: len(probe.wheel_commands) > 10 and np.any(probe.wheel_commands[-1]))
        assert probe.wheel_commands[-1] == pytest.approx([3.0, 3.0])


async def test_odometry_integrates_wheel_positions_from_joint_states():
    async with Runtime() as rt:
        controller = DiffDriveController(
            parameter_overrides={"wheel_radius": 0.1, "wheel_separation": 0.5, "publish_tf": False}
        )
        probe = Probe()
        rt.add_node(controller, executor="priority")
        rt.add_node(probe)
        # both wheels turn 10 rad over 1 s: 1 m straight ahead
        for i in range(11):
            msg = JointState()
            msg.header.stamp.sec, msg.header.stamp.nanosec = 100, i * 100_000_000 % 1_000_000_000
            if i == 10:
                msg.header.stamp.sec, msg.header.stamp.nanosec = 101, 0
            msg.name = ["right_wheel_joint", "left_wheel_joint"]  # order differs on purpose
            msg.position = np.array([float(i), float(i)])
            msg.velocity = np.array([10.0, 10.0])
            probe.joint_pub.publish(msg)
            await wait_until(lambda i=i: len(probe.odom) > i)
        assert len(probe.odom) == 11  # the first reading only sets the reference
        odom = probe.odom[-1]
        assert odom.header.frame_id == "odom" and odom.child_frame_id == "base_link"
        assert odom.pose.pose.position.x == pytest.approx(1.0)
        assert odom.pose.pose.position.y == pytest.approx(0.0)
        assert odom.twist.twist.linear.x == pytest.approx(1.0)
        covariance = np.asarray(odom.pose.covariance).reshape(6, 6)
        assert covariance[0, 0] > 0 and covariance[0, 0] > np.asarray(probe.odom[0].pose.covariance)[0]


async def test_odometry_of_a_turn_on_the_spot():
    async with Runtime() as rt:
        controller = DiffDriveController(
            parameter_overrides={"wheel_radius": 0.1, "wheel_separation": 0.5, "publish_tf": False}
        )
        probe = Probe()
        rt.add_node(controller, executor="priority")
        rt.add_node(probe)
        quarter = (math.pi / 2) * 0.25 / 0.1  # wheel angle for a quarter turn
        for i, angle in enumerate([0.0, quarter]):
            msg = JointState()
            msg.header.stamp.sec = 10 + i
            msg.name = ["left_wheel_joint", "right_wheel_joint"]
            msg.position = np.array([-angle, angle])
            probe.joint_pub.publish(msg)
        await wait_until(lambda: len(probe.odom) == 2)
        q = probe.odom[-1].pose.pose.orientation
        assert 2 * math.atan2(q.z, q.w) == pytest.approx(math.pi / 2)
        assert probe.odom[-1].pose.pose.position.x == pytest.approx(0.0, abs=1e-12)


def test_controller_rejects_wrong_number_of_joint_names():
    with pytest.raises(ValueError, match=r"^joint_names must name 4 wheels for Mecanum, got 2: \['a', 'b'\]$"):
        MecanumController(parameter_overrides={"joint_names": ["a", "b"]})


async def test_odometry_is_broadcast_as_odom_to_base_link_on_tf():
    from aiorobot.msgs.tf2_msgs import TFMessage

    async with Runtime() as rt:
        controller = DiffDriveController(parameter_overrides={"wheel_radius": 0.1, "base_frame_id": "base_footprint"})
        probe = Probe()
        transforms = []
        probe.create_subscription(TFMessage, "/tf", lambda m: transforms.extend(m.transforms), 100)
        rt.add_node(controller, executor="priority")
        rt.add_node(probe)
        for i, angle in enumerate([0.0, 5.0]):
            msg = JointState()
            msg.header.stamp.sec = 1 + i
            msg.name = ["left_wheel_joint", "right_wheel_joint"]
            msg.position = np.array([angle, angle])
            probe.joint_pub.publish(msg)
        await wait_until(lambda: len(transforms) == 2)
        t = transforms[-1]
        assert (t.header.frame_id, t.child_frame_id) == ("odom", "base_footprint")
        assert t.transform.translation.x == pytest.approx(0.5)
        assert t.header.stamp.sec == 2


async def test_limits_change_live_and_geometry_is_read_only():
    from aiorobot import Parameter

    async with Runtime() as rt:
        controller = DiffDriveController(
            parameter_overrides={"max_linear_x": 0.3, "max_accel_x": 1000.0, "wheel_radius": 0.1}
        )
        probe = Probe()
        rt.add_node(controller, executor="priority")
        rt.add_node(probe)
        probe.streaming = twist(vx=5.0)
        await wait_until(lambda: probe.wheel_commands and probe.wheel_commands[-1][0] == pytest.approx(3.0))
        [result] = controller.set_parameters([Parameter("max_linear_x", 0.5)])
        assert result.successful
        await wait_until(lambda: probe.wheel_commands[-1][0] == pytest.approx(5.0))
        [result] = controller.set_parameters([Parameter("wheel_radius", 0.2)])
        assert not result.successful and "read" in result.reason.lower()
        assert controller.kinematics.wheel_radius == 0.1
