"""MPPI against nav2_mppi_controller's definitions (rollouts, critics, the update) and in closed loop
on a kinematic base: straight and curved paths, an obstacle on the path, the three motion models."""

from __future__ import annotations

import math

import numpy as np
import pytest

from aiorobot.nav import LETHAL_OBSTACLE, Costmap, Mppi, MppiCommand, MppiParameters
from aiorobot.nav import _mppi_kernels as k

#: small batches keep closed-loop tests fast; the bench row runs Nav2's 1000 x 56
FAST = {"batch_size": 400, "time_steps": 56}


def _line(length: float = 2.5, step: float = 0.05, y: float = 0.0) -> np.ndarray:
    x = np.arange(0.0, length + 1e-9, step)
    return np.column_stack([x, np.full_like(x, y), np.zeros_like(x)])


def _free(origin: tuple[float, float] = (-1.0, -2.0), shape: tuple[int, int] = (80, 100)) -> Costmap:
    return Costmap(np.zeros(shape, np.uint8), 0.05, origin)


def _drive(m: Mppi, pose: tuple[float, float, float], cycles: int = 400, costmap: Costmap | None = None) -> tuple[list, list[MppiCommand]]:
    """Integrate the commands on an ideal base every control period; the poses and the commands."""
    x, y, th = pose
    dt = m.p.controller_period
    poses, cmds = [(x, y, th)], []
    for _ in range(cycles):
        c = m.step((x, y, th), m.last_command[0])
        cmds.append(c)
        if c.goal_reached or c.collision_ahead:
            break
        x += (c.linear * math.cos(th) - c.lateral * math.sin(th)) * dt
        y += (c.linear * math.sin(th) + c.lateral * math.cos(th)) * dt
        th += c.angular * dt
        poses.append((x, y, th))
    return poses, cmds


# -- kernels against Nav2's formulas ------------------------------------------------------------


def test_rollout_integrates_with_the_previous_heading_and_limits_acceleration() -> None:
    b, t, dt = 1, 6, 0.1
    cs = np.zeros((3, t))
    cs[0], cs[2] = 1.0, 0.5  # asks for 1 m/s and 0.5 rad/s at once
    accel = np.array([2.0, -2.0, 2.0, -2.0, 1.0])
    cv, v = np.zeros((3, b, t)), np.zeros((3, b, t))
    xs, ys, yaws = np.zeros((b, t)), np.zeros((b, t)), np.zeros((b, t))
    travelled = np.zeros(b)
    k.rollout(np.zeros((3, b, t)), cs, np.zeros(3), np.array([1.0, 2.0, 0.3]), dt, accel, False, cv, v, xs, ys, yaws, travelled)
    # step 0 is the current speed; each later step gains at most ax_max * dt = 0.2 m/s and az_max * dt = 0.1 rad/s
    np.testing.assert_allclose(v[0, 0], [0.0, 0.2, 0.4, 0.6, 0.8, 1.0])
    np.testing.assert_allclose(v[2, 0], [0.0, 0.1, 0.2, 0.3, 0.4, 0.5])
    # x_i += vx_i cos(yaw_{i-1}) dt, yaw_i = yaw0 + sum wz dt (Optimizer::integrateStateVelocities)
    th, x, y = 0.3, 1.0, 2.0
    for i in range(t):
        x += v[0, 0, i] * math.cos(th) * dt
        y += v[0, 0, i] * math.sin(th) * dt
        th += v[2, 0, i] * dt
        assert (xs[0, i], ys[0, i], yaws[0, i]) == pytest.approx((x, y, th), abs=1e-12)
    assert travelled[0] == pytest.approx(np.hypot(np.diff(xs[0]), np.diff(ys[0])).sum())
    # a turn over 0.2 rad a step takes cos and sin: the same poses
    cs[2], accel[4] = 8.0, 100.0
    k.rollout(np.zeros((3, b, t)), cs, np.full(3, 8.0), np.zeros(3), dt, accel, False, cv, v, xs, ys, yaws, travelled)
    th = np.cumsum(v[2, 0] * dt)
    assert xs[0] == pytest.approx(np.cumsum(v[0, 0] * np.cos(np.concatenate(([0.0], th[:-1]))) * dt), abs=1e-12)


def test_update_is_the_softmax_weighted_mean_of_the_noised_controls() -> None:
    cv = np.zeros((3, 3, 2))
    cv[0] = [[0.1, 0.1], [0.2, 0.2], [0.3, 0.3]]
    cs = np.zeros((3, 2))
    costs = np.array([0.0, 1.0, 2.0])
    k.update_control_sequence(costs, cv, cs, 0.0, np.array([0.2, 0.0, 0.4]), 0.5, False)
    w = np.exp(-np.array([0.0, 1.0, 2.0]) / 0.5)
    w /= w.sum()
    assert cs[0] == pytest.approx([w @ [0.1, 0.2, 0.3]] * 2)
    assert not cs[1].any()  # vy stays zero for a non-holonomic model


def test_obstacles_critic_scores_a_collision_and_flags_when_all_collide() -> None:
    static = np.zeros((40, 40), np.uint8)
    static[:, 20] = LETHAL_OBSTACLE  # a wall at x = 1.0..1.05
    cm = Costmap(static, 0.05, (0.0, 0.0))
    xs = np.array([np.linspace(0.2, 0.6, 5), np.linspace(0.2, 1.4, 5)])
    ys = np.full((2, 5), 1.0)
    costs = np.zeros(2)
    dist = k.obstacle_distances(0.22, 3.0, 0.55)
    all_collide = k.obstacles_critic(xs, ys, cm.cost, 0.0, 0.0, 0.05, True, dist, 0.55, 0.1, False, 20.0, 1.5,
                                     100000.0, 1, costs)
    assert not all_collide
    assert costs[1] >= 20.0 * 100000.0 and costs[0] < 1000.0
    costs[:] = 0.0
    assert k.obstacles_critic(xs[1:], ys[1:], cm.cost, 0.0, 0.0, 0.05, True, dist, 0.55, 0.1, False, 20.0, 1.5,
                              100000.0, 1, costs[1:])


def test_furthest_reached_point_is_bounded_by_the_distance_travelled() -> None:
    path = _line(2.0)
    dist = np.arange(len(path)) * 0.05
    xs = np.array([[0.0, 0.5, 1.0], [0.0, 0.1, 0.2]])
    ys = np.array([[0.0, 0.0, 0.0], [0.0, 1.0, 0.0]])  # travels 2.0 m but ends at x = 0.2
    travelled = np.array([1.0, 2.0])
    assert k.furthest_reached_path_point(xs, ys, travelled, path, dist) == 20
    assert k.furthest_reached_path_point(xs[1:], ys[1:], travelled[1:], path, dist) == 4


# -- parameters --------------------------------------------------------------------------------


def test_parameters_take_nav2_names_and_refuse_unknown_ones_with_a_suggestion() -> None:
    p = MppiParameters.from_dict({"batch_size": 2000, "vx_max": 0.3, "GoalCritic.cost_weight": 7.0,
                                  "critics": ["GoalCritic", "PathFollowCritic"], "motion_model": "Omni"})
    assert (p.batch_size, p.vx_max, p.critic("GoalCritic")["cost_weight"], p.critics) == (
        2000, 0.3, 7.0, ("GoalCritic", "PathFollowCritic"))
    assert p.holonomic
    with pytest.raises(ValueError, match=r"^unknown MPPI parameter 'vx_maxx'; did you mean 'vx_max'\?$"):
        MppiParameters.from_dict({"vx_maxx": 1.0})
    with pytest.raises(ValueError, match=r"^unknown GoalCritic parameter 'cost_weigth'; did you mean 'cost_weight'\?$"):
        MppiParameters.from_dict({"GoalCritic.cost_weigth": 1.0})
    with pytest.raises(ValueError, match=r"unknown critic 'CostCritic'"):
        MppiParameters(critics=("CostCritic",))
    with pytest.raises(ValueError, match=r"expected one of DiffDrive, Omni, Ackermann, found 'omni'; did you mean 'Omni'\?"):
        MppiParameters(motion_model="omni")
    with pytest.raises(ValueError, match=r"longer than model_dt 0.05 s; set model_dt to the controller period"):
        MppiParameters(controller_period=0.1)


# -- closed loop -----------------------------------------------------------------------------


def test_a_straight_path_is_followed_to_the_goal_within_the_limits() -> None:
    m = Mppi(MppiParameters(**FAST), _free())
    m.set_plan(_line())
    poses, cmds = _drive(m, (0.0, 0.0, 0.0))
    assert cmds[-1].goal_reached
    x, y, _ = poses[-1]
    assert math.hypot(x - 2.5, y) <= 0.25
    assert max(abs(p[1]) for p in poses) < 0.1  # stays on the line
    vx = np.array([c.linear for c in cmds[:-1]])  # the last is the stop at the goal
    assert vx.max() <= 0.5 + 1e-9 and vx.max() > 0.4  # reaches close to vx_max, never above
    assert np.all(np.abs(np.diff(vx)) <= 3.0 * 0.05 + 1e-9)  # ax_max between commands
    assert all(abs(c.angular) <= 1.9 + 1e-9 for c in cmds)


def test_a_path_behind_the_robot_is_taken_forward_after_turning() -> None:
    m = Mppi(MppiParameters(**FAST), _free(origin=(-3.0, -2.0), shape=(80, 120)))
    path = _line(2.0)
    path[:, 0] *= -1.0
    path[:, 2] = math.pi
    m.set_plan(path)
    poses, cmds = _drive(m, (0.0, 0.0, 0.0))
    assert cmds[-1].goal_reached
    assert math.hypot(poses[-1][0] + 2.0, poses[-1][1]) <= 0.25
    backwards = sum(max(-c.linear, 0.0) for c in cmds) * 0.05
    forwards = sum(max(c.linear, 0.0) for c in cmds) * 0.05
    assert backwards < 0.5 and forwards > 1.5  # PreferForward and PathAngle: turn, then drive forward


def test_an_obstacle_on_the_path_is_driven_around_without_touching_it() -> None:
    static = np.zeros((80, 100), np.uint8)
    # a 20 cm box at x = 0.9..1.1, y = 0.05..0.25, seen after planning: the path runs inside its inscribed
    # radius. (Straight across the path, MPPI stops before it as Nav2's does, and the server's replanning
    # at 1 Hz takes the robot round: tests/nav/test_mppi_server.py.)
    static[41:45, 38:42] = LETHAL_OBSTACLE
    cm = Costmap(static, 0.05, (-1.0, -2.0))
    m = Mppi(MppiParameters(**FAST), cm)
    m.set_plan(_line())
    poses, cmds = _drive(m, (0.0, 0.0, 0.0), costmap=cm)
    assert cmds[-1].goal_reached
    assert max(cm.cost_at(x, y) for x, y, _ in poses) < 253  # never inside the inscribed radius of the box
    assert min(p[1] for p in poses) < -0.2  # it went round on the free side


def test_a_robot_walled_in_gets_a_stop_and_collision_ahead() -> None:
    static = np.zeros((80, 100), np.uint8)
    static[:, 24] = LETHAL_OBSTACLE  # a wall 0.2 m ahead, across the whole map
    cm = Costmap(static, 0.05, (-1.0, -2.0))
    m = Mppi(MppiParameters(**FAST, vx_min=0.0), cm)
    m.set_plan(_line())
    cmd = m.step((0.0, 0.0, 0.0), 0.0)
    assert cmd == MppiCommand(0.0, 0.0, collision_ahead=True)


def test_omni_moves_sideways_to_a_goal_on_its_left() -> None:
    m = Mppi(MppiParameters(**FAST, motion_model="Omni"), _free())
    y = np.arange(0.0, 1.5 + 1e-9, 0.05)
    m.set_plan(np.column_stack([np.zeros_like(y), y, np.zeros_like(y)]))  # keep facing +x
    poses, cmds = _drive(m, (0.0, 0.0, 0.0))
    assert cmds[-1].goal_reached
    assert max(c.lateral for c in cmds) > 0.2
    assert all(abs(c.lateral) <= 0.5 + 1e-9 for c in cmds)


def test_ackermann_never_turns_tighter_than_its_radius() -> None:
    m = Mppi(MppiParameters(**FAST, motion_model="Ackermann", min_turning_r=1.0, vx_min=0.0), _free())
    t = np.linspace(0.0, math.pi / 2, 80)
    m.set_plan(np.column_stack([1.5 * np.sin(t), 1.5 * (1 - np.cos(t)), t]))  # a 1.5 m radius quarter turn
    poses, cmds = _drive(m, (0.0, 0.0, 0.0))
    assert cmds[-1].goal_reached
    assert all(abs(c.angular) <= abs(c.linear) / 1.0 + 1e-9 for c in cmds)
    assert all(c.lateral == 0.0 for c in cmds)


def test_the_same_seed_gives_the_same_commands() -> None:
    def run() -> list[float]:
        m = Mppi(MppiParameters(**FAST, seed=3, regenerate_noises=True), _free())
        m.set_plan(_line())
        return [m.step((0.0, 0.0, 0.0), 0.0).linear for _ in range(5)]

    assert run() == run()


def test_set_speed_limit_scales_the_velocity_limits_as_nav2s_optimizer() -> None:
    from aiorobot.nav._mppi import Mppi

    mppi = Mppi()
    base = mppi.p
    mppi.set_speed_limit(50.0, True)
    assert (mppi.p.vx_max, mppi.p.vx_min, mppi.p.wz_max) == (base.vx_max * 0.5, base.vx_min * 0.5, base.wz_max * 0.5)
    mppi.set_speed_limit(base.vx_max / 4, False)
    assert mppi.p.vx_max == base.vx_max / 4 and mppi.p.wz_max == base.wz_max / 4
    mppi.set_speed_limit(0.0, False)  # NO_SPEED_LIMIT
    assert mppi.p is base
