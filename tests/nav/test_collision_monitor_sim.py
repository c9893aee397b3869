"""The collision monitor in the simulator: a box pushed into the robot's path stops it before contact.

The navigation server drives with Regulated Pure Pursuit, its own collision detection turned off
(the monitor must act whatever the controller says); its /cmd_vel goes to the monitor, which
sends /cmd_vel to the simulator. Odometry is exact and map -> odom is the start pose, so tf's
base_link is the ground truth and the test does not depend on a localiser.
"""

from __future__ import annotations

import asyncio
import math
from typing import Any

import numpy as np
import pytest

from aiorobot import Node, Runtime
from aiorobot.nav import ActionType, CollisionMonitorNode, NavigationServer, Navigator, pose_stamped
from aiorobot.sim import Simulator

START = (-2.0, 0.0, 0.0)
ROBOT_RADIUS = 0.22
BOX_HALF = 0.1
#: the stop polygon in front of the base (its footprint's width, 0.2 m beyond its front)
STOP_POINTS = "[[0.42, 0.22], [0.42, -0.22], [0.0, -0.22], [0.0, 0.22]]"


def monitor_parameters(**extra: Any) -> dict[str, Any]:
    return {
        "cmd_vel_in_topic": "cmd_vel_nav", "cmd_vel_out_topic": "cmd_vel", "state_topic": "collision_monitor_state",
        "base_frame_id": "base_link", "polygons": ["PolygonStop"],
        "PolygonStop.type": "polygon", "PolygonStop.points": STOP_POINTS, "PolygonStop.action_type": "stop",
        "PolygonStop.min_points": 4, "observation_sources": ["scan"], "scan.type": "scan", "scan.topic": "scan", **extra,
    }


def send_map_to_odom(node: Node) -> None:
    """map -> odom at the start pose: with exact odometry (see :func:`simulator`) tf's base_link is the truth."""
    from aiorobot.msgs.geometry_msgs import TransformStamped
    from aiorobot.tf import StaticTransformBroadcaster

    t = TransformStamped()
    t.header.frame_id, t.child_frame_id = "map", "odom"
    t.transform.translation.x, t.transform.translation.y = START[0], START[1]
    t.transform.rotation.w = 1.0
    StaticTransformBroadcaster(node).send_transform(t)


def simulator(seed: int) -> Simulator:
    """The box world in lock-step, exact odometry broadcast on tf, no camera."""
    return Simulator(parameter_overrides={
        "world": "box", "start": list(START), "real_time_factor": 0.0, "seed": seed, "publish_odom_tf": True,
        "odom_scale_error": 0.0, "odom_noise_std": 0.0, "camera_rate": 0.0, "robot_radius": ROBOT_RADIUS})


class Pusher(Node):
    """Pushes a box into the robot's path, 1 m ahead of it (``offset_y`` to the side), once it drives at
    speed; watches the gap."""

    def __init__(self, sim: Simulator, push_at_x: float, offset_y: float) -> None:
        super().__init__("pusher")
        from aiorobot.msgs.nav2_msgs import CollisionMonitorState
        from aiorobot.msgs.nav_msgs import Odometry

        self.sim, self.push_at_x, self.offset_y = sim, push_at_x, offset_y
        self.box_x: float | None = None
        self.box_y = 0.0
        self.pushed_at: float | None = None
        self.min_gap = math.inf  # robot disc to the box, after the push
        self.stopped_gap: float | None = None  # that gap when the robot first stood still after the push
        self.stopped_at: float | None = None
        self.states: list[tuple[int, str]] = []
        send_map_to_odom(self)
        self.create_subscription(Odometry, "/ground_truth/odom", self._on_truth, 10)
        self.create_subscription(CollisionMonitorState, "/collision_monitor_state",
                                 lambda m: self.states.append((int(m.action_type), str(m.polygon_name))), 10)

    def _on_truth(self, msg: Any) -> None:
        x, y = msg.pose.pose.position.x, msg.pose.pose.position.y
        speed = math.hypot(msg.twist.twist.linear.x, msg.twist.twist.linear.y)
        if self.box_x is None:
            if x >= self.push_at_x and speed > 0.4:
                self.box_x, self.box_y = x + 1.0, y + self.offset_y
                self.pushed_at = self.sim.time_ns / 1e9
                self.sim.world.add_obstacle(self.box_x, self.box_y, BOX_HALF)
            return
        dx = max(abs(x - self.box_x) - BOX_HALF, 0.0)
        dy = max(abs(y - self.box_y) - BOX_HALF, 0.0)
        gap = math.hypot(dx, dy) - ROBOT_RADIUS
        self.min_gap = min(self.min_gap, gap)
        if self.stopped_gap is None and speed < 1e-3:
            self.stopped_gap = gap
            self.stopped_at = self.sim.time_ns / 1e9


#: MPPI with its obstacle critic off: like RPP's collision check off, only the monitor can stop the robot
BLIND_MPPI = {"controller": "mppi", "critics": ["ConstraintCritic", "GoalCritic", "GoalAngleCritic", "PathAlignCritic",
                                                 "PathFollowCritic", "PathAngleCritic", "PreferForwardCritic"]}


async def _run(seed: int, controller: str = "rpp") -> tuple[Simulator, Pusher, CollisionMonitorNode]:
    async with Runtime(use_sim_time=True, handle_signals=False) as rt:
        sim = simulator(seed)
        chosen = BLIND_MPPI if controller == "mppi" else {}
        rt.add_node(NavigationServer(parameter_overrides={"use_collision_detection": False, "replan_period": 30.0,
                                                          "desired_linear_vel": 0.5, **chosen,
                                                          "localization_topic": ""},
                                     remappings={"/cmd_vel": "/cmd_vel_nav"}))
        monitor = rt.add_node(CollisionMonitorNode(parameter_overrides=monitor_parameters()), executor="priority")
        rng = np.random.default_rng(seed)  # where the box comes in: along the route, and across it within its width
        pusher = rt.add_node(Pusher(sim, push_at_x=float(rng.uniform(-1.5, -1.0)), offset_y=float(rng.uniform(-0.15, 0.15))))
        nav = rt.add_node(Navigator())
        rt.add_node(sim)
        assert await nav.go_to_pose(pose_stamped(2.5, 0.0, 0.0))
        async with asyncio.timeout(50):  # wall seconds: generous; the loop ends on sim time
            while pusher.pushed_at is None or sim.time_ns / 1e9 < pusher.pushed_at + 2.5:
                assert sim.time_ns / 1e9 < 15.0, "the robot never reached speed at the push point"
                await asyncio.sleep(0.02)
        await nav.cancel_task()
    return sim, pusher, monitor


@pytest.mark.parametrize(("seed", "controller"), [(1, "rpp"), (2, "rpp"), (3, "mppi")])
async def test_a_box_pushed_1_m_ahead_stops_the_robot_before_contact_whatever_the_controller_commands(
    seed: int, controller: str
) -> None:
    sim, pusher, monitor = await _run(seed, controller)
    assert pusher.box_x is not None
    assert sim.body.collisions == 0
    assert pusher.stopped_gap is not None and pusher.stopped_gap > 0.02, pusher.stopped_gap
    assert pusher.min_gap > 0.0
    assert (int(ActionType.STOP), "PolygonStop") in pusher.states
    stats = monitor.statistics()
    assert stats.commands_in > 0 and stats.commands_out > 0
