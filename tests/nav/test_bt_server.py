"""The navigation server's behaviour trees on sim time (the kinematic robot of test_navigation_e2e):
the default tree's planner recovery and recovery round, a goal's own tree, and a tree that cannot load."""

from __future__ import annotations

import math
from pathlib import Path

import cv2
import numpy as np
import pytest

from aiorobot.nav import LETHAL_OBSTACLE, MapServer, NavigationServer, Navigator, TaskResult, pose_stamped
from aiorobot.testing import SimClock

from .test_navigation_e2e import KinematicRobot, _until


def _room_with_a_closed_box(tmp: Path) -> Path:
    """4 m x 4 m at 5 cm, origin (-2, -2); a closed 1 m box of walls around (1.0, 1.0)."""
    img = np.full((80, 80), 254, np.uint8)
    img[:2, :] = img[-2:, :] = img[:, :2] = img[:, -2:] = 0
    # the box: x 0.5..1.5, y 0.5..1.5 -> columns 50..70, image rows 10..30 (rows run from y = +2 down)
    img[10:12, 50:70] = img[28:30, 50:70] = img[10:30, 50:52] = img[10:30, 68:70] = 0
    cv2.imwrite(str(tmp / "boxed.pgm"), img)
    (tmp / "boxed.yaml").write_text("image: boxed.pgm\nresolution: 0.05\norigin: [-2.0, -2.0, 0.0]\n"
                                    "occupied_thresh: 0.65\nfree_thresh: 0.196\nnegate: 0\n")
    return tmp / "boxed.yaml"


@pytest.fixture
async def world(sim_runtime, tmp_path):
    sim = SimClock(sim_runtime)
    await sim.start()
    robot = sim_runtime.add_node(KinematicRobot(-1.2, -1.0, 0.0))
    sim_runtime.add_node(MapServer(yaml_filename=str(_room_with_a_closed_box(tmp_path))))
    server = sim_runtime.add_node(NavigationServer(parameter_overrides={"max_recoveries": 3, "wait_duration": 0.5}))
    nav = sim_runtime.add_node(Navigator())
    await sim.advance(0.2, step_sec=0.02)
    return sim, robot, server, nav


async def test_stale_obstacles_across_the_room_are_cleared_by_the_planner_recovery(world) -> None:
    sim, robot, server, nav = world
    cm = server.costmap
    r, _ = cm.world_to_cell(0.0, 0.0)
    cm.obstacles[r - 2 : r + 2, :] = LETHAL_OBSTACLE  # a band across the room, no scan to clear it: no path
    cm.update()
    assert await nav.go_to_pose(pose_stamped(-1.2, 1.0, math.pi / 2))
    await _until(sim, nav, 40.0)
    assert nav.get_result() is TaskResult.SUCCEEDED  # ComputePathToPose failed, ClearEntireCostmap, replanned
    assert math.hypot(robot.pose[0] + 1.2, robot.pose[1] - 1.0) <= 0.25
    assert server.statistics().recoveries == 0  # clearing in the planner's own retry is not a recovery action


async def test_an_unreachable_goal_runs_the_recovery_round_then_fails_with_the_planners_code(world) -> None:
    sim, robot, server, nav = world
    start = list(robot.pose)
    assert await nav.go_to_pose(pose_stamped(1.0, 1.0, 0.0))  # free, inside the closed box
    await _until(sim, nav, 60.0)
    assert nav.get_result() is TaskResult.FAILED
    assert nav.result.error_code == 208  # ComputePathToPose NO_VALID_PATH
    assert "no path" in nav.result.error_msg and "recoveries did not help" in nav.result.error_msg
    # 3 rounds (max_recoveries): clear both costmaps, spin, wait; the spin and the wait count
    assert server.statistics().recoveries == 2 and nav.get_feedback().number_of_recoveries == 2
    assert abs(math.remainder(robot.pose[2] - start[2], 2 * math.pi)) == pytest.approx(1.57, abs=0.15)  # it spun
    assert robot.cmd == (0.0, 0.0)


async def test_a_goal_can_name_its_own_tree_and_a_bad_one_fails_with_nav2s_code(world, tmp_path) -> None:
    sim, robot, server, nav = world
    tree = tmp_path / "back_and_wait.xml"
    tree.write_text('<root BTCPP_format="4" main_tree_to_execute="Main"><BehaviorTree ID="Main">'
                    '<Sequence><BackUp backup_dist="0.2" backup_speed="0.1"/><Wait wait_duration="1.0"/></Sequence>'
                    '</BehaviorTree></root>')
    x0 = robot.pose[0]
    assert await nav.go_to_pose(pose_stamped(1.2, -1.0, 0.0), behavior_tree=str(tree))
    await _until(sim, nav, 20.0)
    assert nav.get_result() is TaskResult.SUCCEEDED  # this tree only backs up and waits
    assert robot.pose[0] == pytest.approx(x0 - 0.2, abs=0.03)
    bad = tmp_path / "bad.xml"
    bad.write_text('<root BTCPP_format="4"><BehaviorTree ID="Main"><Spinn/></BehaviorTree></root>')
    assert await nav.go_to_pose(pose_stamped(1.2, -1.0, 0.0), behavior_tree=str(bad))
    await _until(sim, nav, 5.0)
    assert nav.get_result() is TaskResult.FAILED and nav.result.error_code == 9001
    assert f"{bad}: unknown node <Spinn> in tree 'Main'; did you mean <Spin>?" in nav.result.error_msg
    assert await nav.go_to_pose(pose_stamped(1.2, -1.0, 0.0), behavior_tree=str(tmp_path / "missing.xml"))
    await _until(sim, nav, 5.0)
    assert nav.get_result() is TaskResult.FAILED and "missing.xml: cannot read the behaviour tree" in nav.result.error_msg


async def test_a_newer_goal_preempts_the_running_one_of_the_same_action(world, sim_runtime) -> None:
    sim, robot, server, nav = world
    other = sim_runtime.add_node(Navigator("second_navigator"))
    assert await nav.go_to_pose(pose_stamped(-1.2, 1.2, 0.0))
    await sim.advance(1.0, step_sec=0.05)
    assert not await other.follow_waypoints([pose_stamped(-1.5, -1.0, 0.0)])  # another action waits its turn: refused
    assert await other.go_to_pose(pose_stamped(-0.5, -1.0, 0.0))  # the same action: takes over
    await _until(sim, other, 30.0)
    assert other.get_result() is TaskResult.SUCCEEDED
    assert nav.get_result() is TaskResult.FAILED and nav.result.error_msg == "preempted by a newer goal"
    assert math.hypot(robot.pose[0] + 0.5, robot.pose[1] + 1.0) <= 0.25
