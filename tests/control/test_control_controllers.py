from __future__ import annotations

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

from aiorobot.control import PID, GoToGoal, PurePursuit, VelocitySmoother, integrate_twist


def test_pid_proportional_only():
    pid = PID(2.0)
    assert pid.update(1.0, 0.25, 0.1) == pytest.approx(1.5)


def test_pid_output_is_clamped():
    pid = PID(10.0, output_limits=(-1.0, 2.0))
    assert pid.update(5.0, 0.0, 0.1) == 2.0
    assert pid.update(-5.0, 0.0, 0.1) == -1.0


def test_pid_anti_windup_leaves_saturation_as_soon_as_error_reverses():
    pid = PID(1.0, 5.0, output_limits=(-1.0, 1.0))
    for _ in range(1000):  # 10 s of saturation with a large error
        assert pid.update(10.0, 0.0, 0.01) == 1.0
    assert pid.integral <= 1.0
    # the error flips sign: an integrator that wound up would hold the output at +1 for seconds
    output = pid.update(0.0, 0.5, 0.01)
    assert output < 1.0
    outputs = [pid.update(0.0, 0.5, 0.01) for _ in range(30)]
    assert outputs[-1] < 0.0


def test_pid_integral_removes_steady_state_error_on_a_first_order_plant():
    pid = PID(0.5, 2.0, output_limits=(-10, 10))
    y = 0.0
    for _ in range(3000):
        u = pid.update(1.0, y, 0.01)
        y += (u - 0.5 * y) * 0.01 * 5  # plant with gain 2 and a disturbance-free first-order lag
    assert y == pytest.approx(1.0, abs=1e-3)


def test_pid_derivative_acts_on_measurement_not_setpoint():
    pid = PID(0.0, 0.0, 1.0)
    pid.update(0.0, 0.0, 0.1)
    assert pid.update(100.0, 0.0, 0.1) == 0.0  # setpoint step: no kick
    assert pid.update(100.0, 1.0, 0.1) == pytest.approx(-10.0)  # measurement rising


def test_pid_rejects_bad_limits():
    with pytest.raises(ValueError, match=r"^output_limits must be \(low, high\) with low < high, got \(1\.0, -1\.0\)$"):
        PID(1.0, output_limits=(1.0, -1.0))


def test_smoother_respects_acceleration_and_velocity_limits():
    smoother = VelocitySmoother(max_velocity=[0.5, 0.3, 1.0], max_acceleration=[1.0, 0.5, 2.0])
    previous = np.zeros(3)
    for _ in range(100):
        out = smoother.update([2.0, -2.0, 5.0], 0.05)
        assert np.all(np.abs(out - previous) <= np.array([1.0, 0.5, 2.0]) * 0.05 + 1e-12)
        assert np.all(np.abs(out) <= np.array([0.5, 0.3, 1.0]) + 1e-12)
        previous = out
    assert_allclose(previous, [0.5, -0.3, 1.0])


def test_smoother_uses_deceleration_limit_when_slowing_and_through_zero():
    smoother = VelocitySmoother(max_velocity=2.0, max_acceleration=1.0, max_deceleration=10.0)
    smoother.reset([1.0, 0.0, 0.0])
    assert smoother.update([0.0, 0.0, 0.0], 0.05)[0] == pytest.approx(0.5)
    smoother.reset([1.0, 0.0, 0.0])
    # 0.1 s to stop at 10 m/s^2, then 0.1 s speeding up backward at 1 m/s^2
    assert smoother.update([-1.0, 0.0, 0.0], 0.2)[0] == pytest.approx(-0.1)


def test_smoother_limit_error_message():
    with pytest.raises(ValueError, match=r"^max_acceleration must be > 0 on every axis \(inf for no limit\), got \[1\.0, 0\.0, 1\.0\]$"):
        VelocitySmoother(1.0, [1.0, 0.0, 1.0])


def unicycle_loop(controller_step, pose, dt=0.02, steps=3000):
    for _ in range(steps):
        cmd = controller_step(pose)
        if cmd.done:
            return pose, True
        pose = integrate_twist(pose, [cmd.linear, 0.0, cmd.angular], dt)
    return pose, False


def test_go_to_goal_rotates_in_place_when_goal_is_behind():
    cmd = GoToGoal(heading_threshold_rad=0.5).compute([0, 0, 0], [-1.0, 0.1])
    assert cmd.linear == 0.0 and cmd.angular > 0.0 and not cmd.done


@pytest.mark.parametrize("goal", [(2.0, 1.0), (-1.5, -0.5), (0.0, -2.0)])
def test_go_to_goal_reaches_goal_in_kinematic_loop(goal):
    ctrl = GoToGoal(goal_tolerance_m=0.05)
    pose, done = unicycle_loop(lambda p: ctrl.compute(p, goal), np.array([0.0, 0.0, 0.3]))
    assert done
    assert math.hypot(pose[0] - goal[0], pose[1] - goal[1]) <= 0.05


def test_go_to_goal_turns_to_final_yaw():
    ctrl = GoToGoal()
    pose, done = unicycle_loop(lambda p: ctrl.compute(p, (1.0, 0.0, math.pi / 2)), np.zeros(3))
    assert done and pose[2] == pytest.approx(math.pi / 2, abs=0.05)


def test_pure_pursuit_follows_an_l_shaped_path():
    xs = np.linspace(0, 2, 21)
    path = np.concatenate([np.stack([xs, 0 * xs], 1), np.stack([2 + 0 * xs[1:], xs[1:]], 1)])
    follower = PurePursuit(path, lookahead_m=0.3, linear_speed=0.4, goal_tolerance_m=0.05)
    pose = np.array([0.0, -0.1, 0.0])
    worst = 0.0
    for _ in range(5000):
        cmd = follower.compute(pose)
        if cmd.done:
            break
        pose = integrate_twist(pose, [cmd.linear, 0.0, cmd.angular], 0.02)
        # cross-track error to the polyline
        d_first = abs(pose[1]) if pose[0] <= 2 else math.hypot(pose[0] - 2, pose[1])
        d_second = abs(pose[0] - 2) if pose[1] >= 0 else math.hypot(pose[0] - 2, pose[1])
        worst = max(worst, min(d_first, d_second))
    assert cmd.done
    assert math.hypot(pose[0] - 2, pose[1] - 2) <= 0.05
    assert worst < 0.25


def test_pure_pursuit_accepts_n_by_3_and_rejects_bad_shapes():
    PurePursuit(np.zeros((3, 3)) + [[0, 0, 0], [1, 0, 0], [2, 0, 0]])
    with pytest.raises(ValueError, match=r"^path must have shape \(N, 2\) as \(x, y\) or \(N, 3\) with N >= 1, got shape \(4,\)$"):
        PurePursuit(np.zeros(4))
