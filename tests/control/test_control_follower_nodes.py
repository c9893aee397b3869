"""Go-to-goal and pure-pursuit nodes closing the loop over a kinematic base simulated on topics."""

from __future__ import annotations

import math

import numpy as np
import pytest

try:
    from aiorobot import Node, Runtime
except ImportError:  # the runtime is not exported yet
    pytest.skip("needs aiorobot.Node and aiorobot.Runtime", allow_module_level=True)

from aiorobot.msgs.geometry_msgs import PoseStamped, Twist  # noqa: E402
from aiorobot.msgs.nav_msgs import Odometry, Path  # noqa: E402

from aiorobot.control import GoToGoalController, PurePursuitController, integrate_twist, path_from_msg  # noqa: E402
from _helpers import wait_until  # noqa: E402




class UnicycleSim(Node):
    """Integrates /cmd_vel exactly over each step of its own clock and publishes /odom."""

    def __init__(self, **kw):
        super().__init__("unicycle_sim", **kw)
        self.pose = np.zeros(3)
        self.twist = np.zeros(3)
        self.pub = self.create_publisher(Odometry, "/odom", 10)
        self.create_subscription(Twist, "/cmd_vel", self.on_cmd, 10)
        self._last_ns = None
        self.create_timer(0.01, self.tick)

    def on_cmd(self, msg):
        self.twist = np.array([msg.linear.x, 0.0, msg.angular.z])

    def tick(self):
        now = self.now().nanoseconds
        if self._last_ns is not None:
            self.pose = integrate_twist(self.pose, self.twist, (now - self._last_ns) * 1e-9)
        self._last_ns = now
        msg = Odometry()
        msg.header.frame_id = "odom"
        msg.pose.pose.position.x, msg.pose.pose.position.y = self.pose[:2]
        msg.pose.pose.orientation.z = math.sin(self.pose[2] / 2)
        msg.pose.pose.orientation.w = math.cos(self.pose[2] / 2)
        self.pub.publish(msg)


class Commander(Node):
    def __init__(self, **kw):
        super().__init__("commander", **kw)
        self.goal_pub = self.create_publisher(PoseStamped, "/goal_pose", 10)
        self.path_pub = self.create_publisher(Path, "/plan", 10)


async def test_go_to_goal_node_drives_the_base_to_the_goal():
    async with Runtime() as rt:
        sim, commander = UnicycleSim(), Commander()
        controller = GoToGoalController(parameter_overrides={"max_linear": 1.0, "max_angular": 3.0, "rate_hz": 50.0})
        rt.add_node(sim)
        rt.add_node(commander)
        rt.add_node(controller, executor="priority")
        await wait_until(lambda: controller.pose is not None)
        goal = PoseStamped()
        goal.header.frame_id = "odom"
        goal.pose.position.x, goal.pose.position.y = -0.4, 0.6  # behind and to the left: turns first
        goal.pose.orientation.w = 1.0
        commander.goal_pub.publish(goal)
        await wait_until(lambda: controller.goals_reached == 1)
        await wait_until(lambda: not np.any(sim.twist))  # the zero command arrived
        assert math.hypot(sim.pose[0] + 0.4, sim.pose[1] - 0.6) < 0.1


async def test_goal_in_another_frame_is_refused(caplog):
    async with Runtime() as rt:
        sim, commander = UnicycleSim(), Commander()
        controller = GoToGoalController()
        rt.add_node(sim)
        rt.add_node(commander)
        rt.add_node(controller)
        await wait_until(lambda: controller.odom_frame_id == "odom")
        goal = PoseStamped()
        goal.header.frame_id = "map"
        commander.goal_pub.publish(goal)
        await wait_until(lambda: any("is in frame 'map' but odometry is in 'odom'" in r.getMessage() for r in caplog.records))
        assert not controller.active


async def test_pure_pursuit_node_follows_a_path_to_its_end():
    async with Runtime() as rt:
        sim, commander = UnicycleSim(), Commander()
        controller = PurePursuitController(
            parameter_overrides={"linear_speed": 0.8, "lookahead_m": 0.3, "max_angular": 3.0, "rate_hz": 50.0}
        )
        rt.add_node(sim)
        rt.add_node(commander)
        rt.add_node(controller, executor="priority")
        await wait_until(lambda: controller.pose is not None)
        path = Path()
        path.header.frame_id = "odom"
        for t in np.linspace(0.0, math.pi / 2, 20):  # a quarter circle of radius 1 from (0, 0) heading +x
            pose = PoseStamped()
            pose.pose.position.x, pose.pose.position.y = math.sin(t), 1.0 - math.cos(t)
            path.poses.append(pose)
        assert path_from_msg(path).shape == (20, 3)
        commander.path_pub.publish(path)
        radial_errors = []

        def done():
            radial_errors.append(abs(math.hypot(sim.pose[0], sim.pose[1] - 1.0) - 1.0))
            return controller.goals_reached == 1

        await wait_until(done)
        worst = max(radial_errors)
        assert math.hypot(sim.pose[0] - 1.0, sim.pose[1] - 1.0) < 0.1
        assert worst < 0.1
