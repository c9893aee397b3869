"""Regulated Pure Pursuit against Nav2's regulation functions, and in closed loop."""

from __future__ import annotations

import math

import numpy as np
import pytest

from aiorobot.nav import Costmap, LETHAL_OBSTACLE
from aiorobot.nav._rpp import RegulatedPurePursuit, RppParameters


def _line(length: float = 3.0, step: float = 0.05) -> np.ndarray:
    x = np.arange(0.0, length + 1e-9, step)
    return np.column_stack([x, np.zeros_like(x), np.zeros_like(x)])


def _arc(radius: float, angle: float = math.pi, step: float = 0.02) -> np.ndarray:
    t = np.arange(0.0, angle, step / radius)
    return np.column_stack([radius * np.sin(t), radius * (1 - np.cos(t)), t])


def test_straight_path_is_followed_at_the_desired_speed() -> None:
    rpp = RegulatedPurePursuit()
    rpp.set_plan(_line())
    cmd = rpp.step((0.0, 0.0, 0.0))
    assert cmd.linear == pytest.approx(0.5) and cmd.angular == pytest.approx(0.0)
    assert cmd.carrot == pytest.approx((0.6, 0.0))  # lookahead_dist on the path


def test_curvature_regulation_slows_on_tight_turns_as_nav2() -> None:
    # regulation_functions.hpp curvatureConstraint: v * (1 - |r - r_min| / r_min) for r < r_min
    params = RppParameters(use_rotate_to_heading=False, regulated_linear_scaling_min_speed=0.0)
    rpp = RegulatedPurePursuit(params)
    rpp.set_plan(_arc(0.45))
    cmd = rpp.step((0.0, 0.0, 0.0))
    radius = 1.0 / abs(cmd.angular / cmd.linear)
    expected = 0.5 * (1 - abs(radius - 0.9) / 0.9)
    assert radius < 0.9
    assert cmd.linear == pytest.approx(expected, rel=1e-6)


def test_approach_scaling_near_the_goal_keeps_the_minimum_approach_speed() -> None:
    rpp = RegulatedPurePursuit()
    rpp.set_plan(_line(1.0))
    near = rpp.step((0.7, 0.0, 0.0))  # 0.3 m left of a 0.6 m approach distance
    assert near.linear == pytest.approx(0.5 * 0.3 / 0.6)
    rpp.set_plan(_line(1.0))
    very_near = rpp.step((0.74, 0.0, 0.0))
    assert very_near.linear >= 0.05


def test_a_carrot_behind_the_robot_makes_it_rotate_in_place_first() -> None:
    rpp = RegulatedPurePursuit()
    rpp.set_plan(_line())
    cmd = rpp.step((0.0, 0.0, math.pi))
    assert cmd.rotating and cmd.linear == 0.0 and cmd.angular != 0.0
    assert abs(cmd.angular) <= 3.2 * 0.05 + 1e-9  # max_angular_accel limits the first step


def test_at_the_goal_position_it_turns_to_the_goal_yaw_then_reports_done() -> None:
    rpp = RegulatedPurePursuit()
    path = _line(1.0)
    path[-1, 2] = 1.0
    rpp.set_plan(path)
    cmd = rpp.step((0.95, 0.0, 0.0))
    assert cmd.rotating and cmd.angular > 0
    assert rpp.step((0.95, 0.0, 0.9)).goal_reached


def test_an_obstacle_on_the_arc_stops_the_base() -> None:
    static = np.zeros((60, 100), np.uint8)
    static[28:33, 20] = LETHAL_OBSTACLE  # across the path at x = 1.0
    cm = Costmap(static, 0.05, (0.0, -1.5))
    rpp = RegulatedPurePursuit(RppParameters(lookahead_dist=0.9), cm)
    rpp.set_plan(_line())
    cmd = rpp.step((0.45, 0.0, 0.0))
    assert cmd.collision_ahead and cmd.linear == 0.0


def test_unknown_parameter_names_get_a_suggestion() -> None:
    with pytest.raises(ValueError, match="unknown Regulated Pure Pursuit parameter 'desired_linear_velocity'; did you mean 'desired_linear_vel'"):
        RppParameters.from_dict({"desired_linear_velocity": 0.3})


def test_closed_loop_unicycle_reaches_the_goal_of_an_s_curve() -> None:
    t = np.linspace(0, 2 * math.pi, 300)
    path = np.column_stack([t * 0.6, 0.5 * np.sin(t), np.zeros_like(t)])
    path[:, 2] = np.arctan2(np.gradient(path[:, 1]), np.gradient(path[:, 0]))
    rpp = RegulatedPurePursuit(RppParameters(use_velocity_scaled_lookahead_dist=True))
    rpp.set_plan(path)
    x, y, th, v = 0.0, 0.0, float(path[0, 2]), 0.0
    dt = 0.05
    worst = 0.0
    for _ in range(2000):
        cmd = rpp.step((x, y, th), v)
        if cmd.goal_reached:
            break
        v = cmd.linear
        x += cmd.linear * math.cos(th) * dt
        y += cmd.linear * math.sin(th) * dt
        th += cmd.angular * dt
        worst = max(worst, float(np.min(np.hypot(path[:, 0] - x, path[:, 1] - y))))
    assert cmd.goal_reached
    assert math.hypot(x - path[-1, 0], y - path[-1, 1]) <= 0.25
    assert worst < 0.15  # cross-track error stays small
