"""Navigation actions end to end on sim time: a kinematic robot, a map server, the navigation
server and the asyncio BasicNavigator. (The full simulator demo has its own test.)"""

from __future__ import annotations

import math
from pathlib import Path

import cv2
import numpy as np
import pytest

from aiorobot import Node
from aiorobot.nav import MapServer, NavigationServer, Navigator, TaskResult, pose_stamped
from aiorobot.nav._geometry import yaw_quaternion
from aiorobot.testing import SimClock


class KinematicRobot(Node):
    """Integrates /cmd_vel (unicycle) at 50 Hz of sim time and broadcasts map -> base_link."""

    def __init__(self, x: float = 0.0, y: float = 0.0, yaw: float = 0.0) -> None:
        super().__init__("robot")
        from aiorobot.msgs.geometry_msgs import Twist
        from aiorobot.tf import TransformBroadcaster

        self.pose = [x, y, yaw]
        self.cmd = (0.0, 0.0)
        self.last: int | None = None
        self.tf = TransformBroadcaster(self)
        self.create_subscription(Twist, "/cmd_vel", lambda m: setattr(self, "cmd", (m.linear.x, m.angular.z)), 10)
        self.create_timer(0.02, self.step)

    def step(self) -> None:
        from aiorobot.msgs.geometry_msgs import TransformStamped

        now = self.now().nanoseconds
        dt = 0.0 if self.last is None else (now - self.last) / 1e9  # sim time may step coarser than the timer
        self.last = now
        v, w = self.cmd
        self.pose[0] += v * math.cos(self.pose[2]) * dt
        self.pose[1] += v * math.sin(self.pose[2]) * dt
        self.pose[2] += w * dt
        t = TransformStamped()
        t.header.frame_id, t.child_frame_id = "map", "base_link"
        t.header.stamp = self.now().to_msg()
        t.transform.translation.x, t.transform.translation.y = self.pose[0], self.pose[1]
        t.transform.rotation = yaw_quaternion(self.pose[2])
        self.tf.send_transform(t)


def _room(tmp: Path) -> Path:
    """4 m x 4 m at 5 cm, origin (-2, -2); a wall from x = 0 up to y = 0.8 with a passage above."""
    img = np.full((80, 80), 254, np.uint8)
    img[:2, :] = img[-2:, :] = img[:, :2] = img[:, -2:] = 0
    img[24:, 39:41] = 0  # image rows 24.. are y <= 0.8 (rows run from the top, y = +2)
    cv2.imwrite(str(tmp / "room.pgm"), img)
    (tmp / "room.yaml").write_text("image: room.pgm\nresolution: 0.05\norigin: [-2.0, -2.0, 0.0]\noccupied_thresh: 0.65\nfree_thresh: 0.196\nnegate: 0\n")
    return tmp / "room.yaml"


async def _until(sim: SimClock, nav: Navigator, limit_sec: float) -> None:
    t = 0.0
    while not nav.is_task_complete() and t < limit_sec:
        await sim.advance(0.25, step_sec=0.05)
        t += 0.25


@pytest.fixture
async def world(sim_runtime, tmp_path: Path):
    sim = SimClock(sim_runtime)
    await sim.start()
    robot = sim_runtime.add_node(KinematicRobot(-1.2, -1.0, 0.0))
    sim_runtime.add_node(MapServer(yaml_filename=str(_room(tmp_path))))
    server = sim_runtime.add_node(NavigationServer(parameter_overrides={"desired_linear_vel": 0.4}))
    nav = sim_runtime.add_node(Navigator())
    await sim.advance(0.2, step_sec=0.02)
    return sim, robot, server, nav


async def test_navigate_to_pose_goes_around_the_wall_and_succeeds(world) -> None:
    sim, robot, server, nav = world
    assert await nav.go_to_pose(pose_stamped(1.2, -1.0, math.pi / 2))
    await _until(sim, nav, 90.0)
    assert nav.get_result() is TaskResult.SUCCEEDED
    x, y, yaw = robot.pose
    assert math.hypot(x - 1.2, y + 1.0) <= 0.25
    assert abs((yaw - math.pi / 2 + math.pi) % (2 * math.pi) - math.pi) <= 0.25
    assert max(p for p in [server.costmap.cost_at(*xy) for xy in server.last_plan.poses[:, :2]]) < 253
    fb = nav.get_feedback()
    assert fb is not None and fb.navigation_time.sec > 0
    stats = server.statistics()
    assert (stats.navigating, stats.localization_lost, stats.recoveries) == (False, None, fb.number_of_recoveries)


async def test_a_goal_inside_the_wall_fails_with_nav2s_code_and_a_reason(world) -> None:
    sim, _, _, nav = world
    assert await nav.go_to_pose(pose_stamped(0.0, -1.0, 0.0))
    await _until(sim, nav, 10.0)
    assert nav.get_result() is TaskResult.FAILED
    assert nav.result.error_code == 206 and "in or too close to an obstacle" in nav.result.error_msg


async def test_cancel_stops_the_robot_and_ends_canceled(world) -> None:
    sim, robot, _, nav = world
    assert await nav.go_to_pose(pose_stamped(1.2, -1.0, 0.0))
    await sim.advance(2.0, step_sec=0.05)
    import asyncio

    cancel = asyncio.ensure_future(nav.cancel_task())
    await _until(sim, nav, 5.0)
    await cancel
    assert nav.get_result() is TaskResult.CANCELED
    assert robot.cmd == (0.0, 0.0)


async def test_follow_waypoints_reports_each_and_an_empty_list_fails(world) -> None:
    sim, robot, _, nav = world
    assert await nav.follow_waypoints([pose_stamped(-1.2, 0.0, 0.0), pose_stamped(-0.6, 1.2, 0.0)])
    await _until(sim, nav, 60.0)
    assert nav.get_result() is TaskResult.SUCCEEDED
    assert math.hypot(robot.pose[0] + 0.6, robot.pose[1] - 1.2) <= 0.25
    assert nav.get_feedback().current_waypoint == 1
    assert await nav.follow_waypoints([])
    await _until(sim, nav, 2.0)
    assert nav.get_result() is TaskResult.FAILED


async def test_get_path_returns_a_collision_free_path(world) -> None:
    sim, _, _, nav = world
    import asyncio

    fut = asyncio.ensure_future(nav.get_path(pose_stamped(-1.2, -1.0, 0), pose_stamped(1.2, -1.0, 0), use_start=True))
    while not fut.done():
        await sim.advance(0.05, step_sec=0.05)
    path = fut.result()
    assert path is not None and len(path.poses) > 10
    assert max(p.pose.position.y for p in path.poses) > 0.8  # over the wall's end


def _estimate(std_xy: float, std_yaw: float = 0.1):
    from aiorobot.msgs.geometry_msgs import PoseWithCovarianceStamped

    msg = PoseWithCovarianceStamped()
    msg.header.frame_id = "map"
    cov = [0.0] * 36
    cov[0] = cov[7] = std_xy * std_xy
    cov[35] = std_yaw * std_yaw
    msg.pose.covariance = cov
    return msg


async def test_localisation_lost_stops_the_robot_and_aborts_with_the_reason(world, sim_runtime) -> None:
    sim, robot, server, nav = world
    amcl = sim_runtime.add_node(Node("fake_amcl_estimate"))
    from aiorobot.msgs.geometry_msgs import PoseWithCovarianceStamped

    pub = amcl.create_publisher(PoseWithCovarianceStamped, "amcl_pose", 10)
    pub.publish(_estimate(0.05))
    assert await nav.go_to_pose(pose_stamped(1.2, -1.0, 0.0))
    await sim.advance(2.0, step_sec=0.05)
    assert robot.cmd != (0.0, 0.0)  # driving on a good estimate
    moved = list(robot.pose)
    pub.publish(_estimate(1.5))  # AMCL's particles spread: lost
    await sim.advance(0.5, step_sec=0.05)
    assert robot.cmd == (0.0, 0.0) and not nav.is_task_complete()  # stopped at once, waiting for it to come back
    await _until(sim, nav, 10.0)
    assert nav.get_result() is TaskResult.FAILED
    assert nav.result.error_code == 9000 and "localisation lost: position std 1.50 m" in nav.result.error_msg
    assert robot.cmd == (0.0, 0.0) and math.hypot(robot.pose[0] - moved[0], robot.pose[1] - moved[1]) < 0.3
    # a goal sent while lost is aborted before the robot moves
    assert await nav.go_to_pose(pose_stamped(-1.2, 0.0, 0.0))
    await _until(sim, nav, 5.0)
    assert nav.get_result() is TaskResult.FAILED and "not driving" in nav.result.error_msg


async def test_localisation_back_within_the_timeout_drives_on(world, sim_runtime) -> None:
    sim, robot, server, nav = world
    amcl = sim_runtime.add_node(Node("fake_amcl_estimate"))
    from aiorobot.msgs.geometry_msgs import PoseWithCovarianceStamped

    pub = amcl.create_publisher(PoseWithCovarianceStamped, "amcl_pose", 10)
    assert await nav.go_to_pose(pose_stamped(-1.2, 0.0, 0.0))
    await sim.advance(1.0, step_sec=0.05)
    pub.publish(_estimate(0.2, std_yaw=2.0))  # heading lost
    await sim.advance(1.0, step_sec=0.05)
    assert robot.cmd == (0.0, 0.0) and server.localization_lost is not None and "heading std" in server.localization_lost
    pub.publish(_estimate(0.05))
    await _until(sim, nav, 60.0)
    assert nav.get_result() is TaskResult.SUCCEEDED


def test_a_bad_localization_type_is_one_clear_error() -> None:
    with pytest.raises(ValueError, match="localization_type: expected 'pose'.*found 'twist'"):
        NavigationServer(parameter_overrides={"localization_type": "twist"})
