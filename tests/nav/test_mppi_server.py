"""The navigation server with ``controller = "mppi"``: Nav2's actions end to end on sim time (the
kinematic robot and room of test_navigation_e2e), a box dropped on the path, and the selection's errors."""

from __future__ import annotations

import math

import pytest

from aiorobot.nav import LETHAL_OBSTACLE, MapServer, Mppi, NavigationServer, Navigator, TaskResult, pose_stamped
from aiorobot.testing import SimClock

from .test_navigation_e2e import KinematicRobot, _room

#: a smaller batch than Nav2's 1000 keeps the test quick on a loaded machine; the bench row runs 1000 x 56
MPPI = {"controller": "mppi", "batch_size": 300, "seed": 1}


@pytest.fixture
async def world(sim_runtime, tmp_path):
    sim = SimClock(sim_runtime)
    await sim.start()
    robot = sim_runtime.add_node(KinematicRobot(-1.2, -1.0, 0.0))
    sim_runtime.add_node(MapServer(yaml_filename=str(_room(tmp_path))))
    server = sim_runtime.add_node(NavigationServer(parameter_overrides=MPPI))
    nav = sim_runtime.add_node(Navigator())
    await sim.advance(0.2, step_sec=0.02)
    return sim, robot, server, nav


async def _drive(sim: SimClock, nav: Navigator, robot: KinematicRobot, limit_sec: float) -> list[tuple[float, float]]:
    """Advance sim time until the task ends; the robot's positions on the way."""
    trace, t = [], 0.0
    while not nav.is_task_complete() and t < limit_sec:
        await sim.advance(0.1, step_sec=0.05)
        trace.append((robot.pose[0], robot.pose[1]))
        t += 0.1
    return trace


async def test_mppi_takes_the_robot_round_the_wall_and_round_a_box_dropped_on_its_path(world) -> None:
    sim, robot, server, nav = world
    assert server.controller == "mppi" and server.mppi_params.batch_size == 300
    assert await nav.go_to_pose(pose_stamped(-1.2, 1.2, 0.0))  # straight up the left of the room
    await sim.advance(1.0, step_sec=0.05)
    # a 20 cm box in the middle of the path, 1 m ahead: the obstacle layer keeps it (no scans clear it)
    cm = server.costmap
    r, c = cm.world_to_cell(-1.2, 0.3)
    cm.obstacles[r - 2 : r + 2, c - 2 : c + 2] = LETHAL_OBSTACLE
    cm.update()
    trace = await _drive(sim, nav, robot, 60.0)
    assert nav.get_result() is TaskResult.SUCCEEDED
    assert math.hypot(robot.pose[0] + 1.2, robot.pose[1] - 1.2) <= 0.25
    assert max(cm.cost_at(x, y) for x, y in trace) < 253  # never within the robot's radius of the box or a wall
    assert max(x for x, _ in trace) > -0.95  # went round it
    # and through the passage over the wall to the other side
    assert await nav.go_to_pose(pose_stamped(1.2, -1.0, -math.pi / 2))
    trace = await _drive(sim, nav, robot, 90.0)
    assert nav.get_result() is TaskResult.SUCCEEDED
    assert math.hypot(robot.pose[0] - 1.2, robot.pose[1] + 1.0) <= 0.25
    assert max(cm.cost_at(x, y) for x, y in trace) < 253


def test_the_controller_parameter_takes_nav2_plugin_names_and_refuses_others() -> None:
    node = NavigationServer(parameter_overrides={"controller": "nav2_mppi_controller::MPPIController",
                                                 "GoalCritic.cost_weight": 7.0, "vx_max": 0.3})
    try:
        assert node.controller == "mppi"
        assert node.mppi_params.vx_max == 0.3 and node.mppi_params.critic("GoalCritic")["cost_weight"] == 7.0
        assert node.mppi_params.model_dt == pytest.approx(0.05)  # the controller period, as Nav2 advises
        assert isinstance(Mppi(node.mppi_params), Mppi)
    finally:
        node.destroy_node()
    with pytest.raises(ValueError, match=r"^parameter controller: expected one of rpp, mppi .*found 'dwb'$"):
        NavigationServer(parameter_overrides={"controller": "dwb"})
    rpp = NavigationServer(parameter_overrides={"batch_size": 10})
    try:
        assert rpp.controller == "rpp" and rpp.unclaimed_parameter_overrides() == ["batch_size"]
    finally:
        rpp.destroy_node()
