"""The rest of nav2_simple_commander's BasicNavigator on Navigator, against the navigation server's
behaviour / controller / planner / smoother / costmap interfaces and the map server, on sim time
(the kinematic robot and room of test_navigation_e2e)."""

from __future__ import annotations

import asyncio
import math
import shutil

import numpy as np
import pytest

from aiorobot.nav import LETHAL_OBSTACLE, MapServer, NavigationServer, Navigator, TaskResult, pose_stamped
from aiorobot.nav._behaviors import smooth_path
from aiorobot.testing import SimClock

from .test_navigation_e2e import KinematicRobot, _room, _until


@pytest.fixture
async def world(sim_runtime, tmp_path):
    sim = SimClock(sim_runtime)
    await sim.start()
    robot = sim_runtime.add_node(KinematicRobot(-1.2, -1.0, 0.0))
    maps = sim_runtime.add_node(MapServer(yaml_filename=str(_room(tmp_path))))
    server = sim_runtime.add_node(NavigationServer())
    nav = sim_runtime.add_node(Navigator())
    await sim.advance(0.2, step_sec=0.02)
    return sim, robot, server, nav, maps


async def _answer(sim: SimClock, coro):
    """Run a query while sim time moves (its servers' waits run on sim time)."""
    task = asyncio.ensure_future(coro)
    while not task.done():
        await sim.advance(0.05, step_sec=0.05)
    return task.result()


def _wrapped(a: float) -> float:
    return (a + math.pi) % (2 * math.pi) - math.pi


async def test_spin_backup_and_drive_on_heading_move_the_base_as_asked(world) -> None:
    sim, robot, _, nav, _ = world
    assert await nav.spin(spin_dist=math.pi / 2, time_allowance=10)
    await _until(sim, nav, 15.0)
    assert nav.getResult() is TaskResult.SUCCEEDED
    assert robot.pose[2] == pytest.approx(math.pi / 2, abs=0.1)
    assert nav.getFeedback().angular_distance_traveled > 1.3
    x, y = robot.pose[:2]
    assert await nav.backup(backup_dist=0.2, backup_speed=0.1)
    await _until(sim, nav, 10.0)
    assert nav.getResult() is TaskResult.SUCCEEDED
    assert math.hypot(robot.pose[0] - x, robot.pose[1] - y) == pytest.approx(0.2, abs=0.03)
    assert robot.pose[1] < y  # facing +y, backing up went to -y
    x, y = robot.pose[:2]
    assert await nav.driveOnHeading(dist=0.3, speed=0.15)
    await _until(sim, nav, 10.0)
    assert nav.getResult() is TaskResult.SUCCEEDED and robot.pose[1] == pytest.approx(y + 0.3, abs=0.03)
    assert robot.cmd == (0.0, 0.0)
    # signs that disagree are refused with Nav2's code and a reason
    assert await nav.drive_on_heading(dist=0.3, speed=-0.1)
    await _until(sim, nav, 2.0)
    assert nav.getResult() is TaskResult.FAILED
    assert nav.result.error_code == 724 and "of one sign" in nav.result.error_msg


async def test_drive_on_heading_stops_before_a_wall_with_collision_ahead(world) -> None:
    sim, robot, _, nav, _ = world
    assert await nav.drive_on_heading(dist=3.0, speed=0.25, time_allowance=30)  # the wall at x = 0 is 1.2 m ahead
    await _until(sim, nav, 30.0)
    assert nav.getResult() is TaskResult.FAILED and nav.result.error_code == 723
    assert robot.pose[0] < -0.2 - 0.05  # stopped short of the wall's inscribed zone


async def test_follow_path_drives_a_given_path_and_a_time_allowance_runs_out(world) -> None:
    sim, robot, _, nav, _ = world
    from aiorobot.msgs.nav_msgs import Path

    path = Path()
    path.header.frame_id = "map"
    path.poses = [pose_stamped(-1.2 + 0.05 * i, -1.0 + 0.04 * i, math.atan2(0.04, 0.05)) for i in range(16)]
    assert await nav.followPath(path)
    await _until(sim, nav, 20.0)
    assert nav.getResult() is TaskResult.SUCCEEDED
    assert math.hypot(robot.pose[0] + 0.45, robot.pose[1] + 0.4) <= 0.25
    assert await nav.spin(spin_dist=6.0, time_allowance=1)
    await _until(sim, nav, 5.0)
    assert nav.getResult() is TaskResult.FAILED and nav.result.error_code == 701  # Spin TIMEOUT
    assert await nav.followPath(Path())
    await _until(sim, nav, 2.0)
    assert nav.getResult() is TaskResult.FAILED and nav.result.error_code == 103  # INVALID_PATH


async def test_path_through_poses_smoothing_and_the_costmaps(world) -> None:
    sim, robot, server, nav, _ = world
    goals = [pose_stamped(-1.2, 1.2, 0.0), pose_stamped(1.2, 1.2, 0.0)]
    path = await _answer(sim, nav.getPathThroughPoses(pose_stamped(-1.2, -1.0, 0.0), goals, use_start=True))
    xy = np.array([(p.pose.position.x, p.pose.position.y) for p in path.poses])
    assert np.hypot(*(xy - [-1.2, 1.2]).T).min() < 0.05 and np.hypot(*(xy[-1] - [1.2, 1.2])) < 0.05  # through both
    smoothed = await _answer(sim, nav.smoothPath(path, check_for_collisions=True))
    assert len(smoothed.poses) == len(path.poses)
    assert (smoothed.poses[0].pose.position.x, smoothed.poses[-1].pose.position.y) == (path.poses[0].pose.position.x,
                                                                                      path.poses[-1].pose.position.y)
    assert await _answer(sim, nav.getPathThroughPoses(pose_stamped(-1.2, -1.0, 0.0), [], use_start=True)) is None
    # an obstacle marked, seen in the costmap, then cleared
    r, c = server.costmap.world_to_cell(-1.2, 0.0)
    server.costmap.obstacles[r, c] = LETHAL_OBSTACLE
    server.costmap.update()
    costmap = await _answer(sim, nav.getGlobalCostmap())
    grid = np.asarray(costmap.data, dtype=np.uint8).reshape(costmap.metadata.size_y, costmap.metadata.size_x)
    assert grid[r, c] == LETHAL_OBSTACLE and costmap.metadata.resolution == pytest.approx(0.05)
    await _answer(sim, nav.clearAllCostmaps())
    local = await _answer(sim, nav.getLocalCostmap())
    assert np.asarray(local.data, dtype=np.uint8).reshape(grid.shape)[r, c] == 0


async def test_change_map_loads_a_new_map_and_a_missing_one_keeps_the_old(world, tmp_path) -> None:
    sim, _, server, nav, maps = world
    other = tmp_path / "other"
    other.mkdir()
    shutil.copy(tmp_path / "room.pgm", other / "room.pgm")
    (other / "room.yaml").write_text((tmp_path / "room.yaml").read_text().replace("origin: [-2.0, -2.0, 0.0]",
                                                                                  "origin: [0.0, 0.0, 0.0]"))
    assert await _answer(sim, nav.changeMap(str(other / "room.yaml")))
    await sim.advance(0.1, step_sec=0.05)
    assert server.map.origin[:2] == (0.0, 0.0)
    assert not await _answer(sim, nav.changeMap(str(tmp_path / "missing.yaml")))
    assert maps.map.origin[:2] == (0.0, 0.0)


async def test_wait_until_nav2_active_waits_for_the_server_and_amcls_pose(world, sim_runtime) -> None:
    sim, _, _, nav, _ = world
    from aiorobot import Node
    from aiorobot.msgs.geometry_msgs import PoseWithCovarianceStamped

    await _answer(sim, nav.waitUntilNav2Active(localizer="robot_localization"))  # no AMCL to wait for
    waiting = asyncio.ensure_future(nav.waitUntilNav2Active())
    await sim.advance(0.5, step_sec=0.05)
    assert not waiting.done()  # no pose on amcl_pose yet
    pub = sim_runtime.add_node(Node("amcl_stand_in")).create_publisher(PoseWithCovarianceStamped, "amcl_pose", 10)
    pub.publish(PoseWithCovarianceStamped())
    while not waiting.done():
        await sim.advance(0.05, step_sec=0.05)
    await waiting


def test_simple_smoother_keeps_the_ends_and_rounds_a_corner() -> None:
    corner = np.array([[0.0, 0.0], [0.5, 0.0], [1.0, 0.0], [1.0, 0.5], [1.0, 1.0]])
    out = smooth_path(corner)
    assert (out[0] == corner[0]).all() and (out[-1] == corner[-1]).all()
    assert out[2, 0] < 1.0 and out[2, 1] > 0.0  # the corner point moved inside
    assert np.hypot(*np.diff(out, axis=0).T).sum() < np.hypot(*np.diff(corner, axis=0).T).sum()
