"""Nav2's preemption on the navigation server: a new goal of the running action (navigate_to_pose,
navigate_through_poses, follow_waypoints) replaces the running one, which ends ABORTED; a goal for
another navigation action while one runs is refused."""

from __future__ import annotations

import asyncio
import math

from aiorobot.nav import Navigator, TaskResult, pose_stamped

from .test_navigation_e2e import _until, world  # noqa: F401 - the fixture


async def test_a_new_goal_preempts_the_running_one_which_ends_aborted(world) -> None:  # noqa: F811
    sim, robot, server, nav = world
    other = server.runtime.add_node(Navigator("second_commander"))
    assert await nav.go_to_pose(pose_stamped(1.2, -1.0, 0.0))  # around the wall
    await sim.advance(1.0, step_sec=0.05)
    assert not nav.is_task_complete() and server.statistics().navigating
    assert await other.go_to_pose(pose_stamped(-1.2, 0.6, math.pi / 2))  # accepted while the first runs
    await _until(sim, nav, 5.0)
    assert nav.get_result() is TaskResult.FAILED  # ABORTED, as Nav2's SimpleActionServer ends it
    await _until(sim, other, 60.0)
    assert other.get_result() is TaskResult.SUCCEEDED
    assert math.hypot(robot.pose[0] + 1.2, robot.pose[1] - 0.6) <= 0.25


async def test_another_navigation_action_is_refused_while_one_runs_and_the_same_one_preempts(world) -> None:  # noqa: F811
    sim, _, server, nav = world
    other = server.runtime.add_node(Navigator("second_commander"))
    assert await nav.follow_waypoints([pose_stamped(1.2, -1.0, 0.0)])
    await sim.advance(0.5, step_sec=0.05)
    assert not await other.go_to_pose(pose_stamped(-1.2, 0.6, 0.0))
    assert not await other.go_through_poses([pose_stamped(-1.2, 0.6, 0.0)])
    assert not nav.is_task_complete()
    assert await other.follow_waypoints([pose_stamped(-1.2, 0.6, 0.0)])  # the same action: preempts
    await _until(sim, nav, 5.0)
    assert nav.get_result() is TaskResult.FAILED
    nav, other = other, nav
    cancel = asyncio.ensure_future(nav.cancel_task())
    await _until(sim, nav, 5.0)
    await cancel
    assert nav.get_result() is TaskResult.CANCELED


async def test_the_navigator_sends_a_new_goal_over_its_running_one_as_basic_navigator(world) -> None:  # noqa: F811
    sim, robot, _, nav = world
    assert await nav.go_to_pose(pose_stamped(1.2, -1.0, 0.0))
    await sim.advance(1.0, step_sec=0.05)
    assert await nav.go_to_pose(pose_stamped(-1.2, 0.6, math.pi / 2))  # the server preempts the first
    await _until(sim, nav, 60.0)
    assert nav.get_result() is TaskResult.SUCCEEDED  # the second goal's, not the aborted first's
    assert math.hypot(robot.pose[0] + 1.2, robot.pose[1] - 0.6) <= 0.25
