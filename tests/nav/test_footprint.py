"""Footprints (nav2_costmap_2d's footprint, robot_radius, padding) in the costmap's collision check,
the planner, Regulated Pure Pursuit and the simulator's collision model."""

from __future__ import annotations

import numpy as np
import pytest

from aiorobot.nav import Costmap, Footprint, RegulatedPurePursuit, RppParameters, plan
from aiorobot.nav._costmap import LETHAL_OBSTACLE

#: a wide, short base: 0.2 m long, 0.7 m wide (inscribed radius 0.1 m)
WIDE = "[[0.1, 0.35], [0.1, -0.35], [-0.1, -0.35], [-0.1, 0.35]]"


def test_footprint_parameters_as_nav2_polygon_padding_radii_and_the_round_default() -> None:
    fp = Footprint.from_parameters("[[0.3, 0.2], [0.3, -0.2], [-0.3, -0.2], [-0.3, 0.2]]", 0.5, 0.01)
    np.testing.assert_allclose(fp.vertices, [[0.31, 0.21], [0.31, -0.21], [-0.31, -0.21], [-0.31, 0.21]])
    assert not fp.is_circular and fp.inscribed_radius == pytest.approx(0.21)
    assert fp.circumscribed_radius == pytest.approx(np.hypot(0.31, 0.21))
    assert Footprint.from_parameters([0.3, 0.2, 0.3, -0.2, -0.3, 0.0], 0.5, 0.0).vertices.shape == (3, 2)
    round_ = Footprint.from_parameters("[]", 0.22)
    assert round_.is_circular and len(round_.vertices) == 16 and round_.inscribed_radius == 0.22
    with pytest.raises(ValueError, match=r"^parameter footprint: expected at least 3 points, found 2$"):
        Footprint.from_parameters("[[0.3, 0.2], [0.3, -0.2]]")


def _room(post: tuple[float, float] | None = None) -> Costmap:
    """4 x 4 m at 5 cm, origin (-2, -2), walls around; an optional one-cell post."""
    static = np.zeros((80, 80), np.uint8)
    static[0, :] = static[-1, :] = static[:, 0] = static[:, -1] = LETHAL_OBSTACLE
    if post is not None:
        static[int((post[1] + 2) / 0.05), int((post[0] + 2) / 0.05)] = LETHAL_OBSTACLE
    return Costmap(static, 0.05, (-2.0, -2.0), footprint=Footprint.from_parameters(WIDE, footprint_padding=0.0))


def test_costmap_takes_the_inscribed_radius_and_checks_the_outline_at_the_pose_heading() -> None:
    cm = _room(post=(0.0, 0.36))
    assert cm.robot_radius == pytest.approx(0.1)
    # the post's cell 0.35-0.4 m to the left: under the wide base's outline facing +x, clear of it facing +y
    assert cm.in_collision(0.0, 0.0, 0.0)
    assert not cm.in_collision(0.0, 0.0, np.pi / 2)
    assert cm.footprint_cost(0.0, 0.0, 0.0) == LETHAL_OBSTACLE
    # a vertex off the map is LETHAL, as Nav2's footprintCost
    assert cm.footprint_cost(-1.95, 0.0, np.pi / 2) == LETHAL_OBSTACLE


def test_round_footprint_keeps_the_centre_cell_check() -> None:
    static = np.zeros((40, 40), np.uint8)
    static[20, 25] = LETHAL_OBSTACLE
    cm = Costmap(static, 0.05, (0.0, 0.0), robot_radius=0.22)
    assert cm.footprint is not None and cm.footprint.is_circular
    assert cm.in_collision(1.1, 1.0, 0.0) and not cm.in_collision(0.5, 0.5, 0.0)


def test_rpp_stops_for_an_obstacle_only_the_wide_footprint_meets() -> None:
    path = np.column_stack([np.linspace(-1.5, 1.5, 61), np.zeros(61), np.zeros(61)])
    params = RppParameters(use_cost_regulated_linear_velocity_scaling=False)
    wide = RegulatedPurePursuit(params, _room(post=(0.3, 0.36)))
    wide.set_plan(path)
    assert wide.step((0.0, 0.0, 0.0), 0.5).collision_ahead
    static = _room(post=(0.3, 0.36)).static
    round_ = RegulatedPurePursuit(params, Costmap(static, 0.05, (-2.0, -2.0), robot_radius=0.1, inflation_radius=0.3))
    round_.set_plan(path)
    assert not round_.step((0.0, 0.0, 0.0), 0.5).collision_ahead


def test_planner_leaves_out_a_gap_the_footprint_does_not_fit_through() -> None:
    # a wall across x = 0 with a 0.5 m gap at y = 1 and a 1.0 m gap at y = -1; the base is 0.7 m wide
    static = np.zeros((80, 80), np.uint8)
    static[0, :] = static[-1, :] = static[:, 0] = static[:, -1] = LETHAL_OBSTACLE
    static[:, 40] = LETHAL_OBSTACLE
    static[55:65, 40] = 0  # y in [0.75, 1.25)
    static[10:30, 40] = 0  # y in [-1.5, -0.5)
    fp = Footprint.from_parameters(WIDE, footprint_padding=0.0)
    cm = Costmap(static, 0.05, (-2.0, -2.0), robot_radius=0.1, inflation_radius=0.3)
    narrow = plan(cm, (-1.0, 1.0), (1.0, 1.0))
    assert np.abs(narrow.poses[:, 1] - 1.0).max() < 0.1  # a point robot takes the short way through the narrow gap
    cm_fp = Costmap(static, 0.05, (-2.0, -2.0), inflation_radius=0.3, footprint=fp)
    p = plan(cm_fp, (-1.0, 1.0), (1.0, 1.0))
    crossing = p.poses[np.argmin(np.abs(p.poses[:, 0]))]
    assert -1.5 <= crossing[1] < -0.5  # through the wide gap
    assert not any(cm_fp.in_collision(*pose) for pose in p.poses[1:])


LONG = [[0.4, 0.1], [0.4, -0.1], [-0.4, -0.1], [-0.4, 0.1]]


@pytest.mark.parametrize(("footprint", "command", "stop_at"), [
    (None, (1.0, 0.0, 0.0), (2.9, 0.0)),  # the disc of radius 0.1 m
    (LONG, (1.0, 0.0, 0.0), (2.6, 0.0)),  # a 0.8 m long base meets the wall (x = 3 m) with its front
    (LONG, (0.0, 1.0, 0.0), (0.0, 2.9)),  # sideways (mecanum), with its 0.1 m half-width
])
def test_simulated_base_collides_with_its_footprint(footprint, command, stop_at) -> None:
    from aiorobot.sim import World
    from aiorobot.sim._robot import RobotBody, make_kinematics

    body = RobotBody(make_kinematics("mecanum"), (0.0, 0.0, 0.0), radius=0.1, footprint=footprint)
    body.set_command(command)
    world = World.load("box")
    for _ in range(400):
        body.step(0.01, world)
    assert body.pose[:2] == pytest.approx(stop_at, abs=0.01) and body.collisions == 1


def test_world_polygon_check_sees_an_obstacle_wholly_inside_the_polygon() -> None:
    from aiorobot.sim import World

    world = World.load("box")
    square = np.array([[-0.5, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]])
    assert world.is_free_polygon(square)
    world.add_obstacle(0.0, 0.0, 0.02)  # one cell in the middle: no edge crosses it
    assert not world.is_free_polygon(square) and world.is_free_polygon(square + 1.0)
    assert not world.is_free_polygon(square * 8)  # past the map's edge


def test_simulator_footprint_parameter_reaches_the_collision_model() -> None:
    from aiorobot.sim import Simulator

    sim = Simulator(parameter_overrides={"footprint": "[[0.2, 0.15], [0.2, -0.15], [-0.2, -0.15], [-0.2, 0.15]]", "camera_rate": 0.0})
    assert sim.body.footprint is not None and sim.body.footprint.tolist() == [[0.2, 0.15], [0.2, -0.15], [-0.2, -0.15], [-0.2, 0.15]]
    with pytest.raises(ValueError, match=r"^footprint: expected \[\] or 3 or more \[x, y\] points such as .*, found '\[\[1, 2\]\]'$"):
        Simulator(parameter_overrides={"footprint": "[[1, 2]]"})


def test_navigation_server_takes_nav2s_footprint_parameters() -> None:
    from aiorobot.nav import NavigationServer

    server = NavigationServer(parameter_overrides={"footprint": "[[0.2, 0.15], [0.2, -0.15], [-0.2, -0.15], [-0.2, 0.15]]",
                                                   "footprint_padding": 0.0})
    assert server.costmap_params["footprint"].inscribed_radius == pytest.approx(0.15)
    with pytest.raises(ValueError, match=r"^navigation_server: parameter footprint: expected at least 3 points, found 1$"):
        NavigationServer(parameter_overrides={"footprint": "[[0.2, 0.15]]"})
