from __future__ import annotations

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

from aiorobot.control import DiffDrive, Mecanum, WheelOdometry, integrate_twist, tick_delta


def closed_form(pose0, vx, vy, omega, t):
    """Pose after holding a body twist for t seconds, from the analytic solution."""
    x0, y0, th0 = pose0
    th = th0 + omega * t
    # integral of R(theta(t)) @ (vx, vy)
    ix = (vx * (math.sin(th) - math.sin(th0)) + vy * (math.cos(th) - math.cos(th0))) / omega
    iy = (-vx * (math.cos(th) - math.cos(th0)) + vy * (math.sin(th) - math.sin(th0))) / omega
    return np.array([x0 + ix, y0 + iy, (th + math.pi) % (2 * math.pi) - math.pi])


@pytest.mark.parametrize("steps", [1, 7, 100])
def test_constant_twist_matches_closed_form_regardless_of_step_count(steps):
    pose0 = np.array([0.3, -0.2, 0.4])
    vx, vy, omega, total = 0.5, 0.2, 0.8, 3.0
    pose = pose0
    for _ in range(steps):
        pose = integrate_twist(pose, [vx, vy, omega], total / steps)
    assert_allclose(pose, closed_form(pose0, vx, vy, omega, total), atol=1e-12)


def test_full_circle_returns_to_start():
    pose = integrate_twist([1.0, 2.0, 0.0], [1.0, 0.0, 2 * math.pi], 1.0)
    assert_allclose(pose[:2], [1.0, 2.0], atol=1e-12)


def test_straight_line_with_zero_omega():
    assert_allclose(integrate_twist([0, 0, math.pi / 2], [2.0, 0.0, 0.0], 0.5), [0.0, 1.0, math.pi / 2], atol=1e-12)


def test_wheel_odometry_from_wheel_speeds_matches_closed_form():
    drive = DiffDrive(0.05, 0.3)
    odom = WheelOdometry(drive)
    wheels = np.array(drive.inverse(0.4, 0.5))
    for _ in range(50):
        odom.update_from_wheel_speeds(wheels, 0.04)
    assert_allclose(odom.pose, closed_form([0, 0, 0], 0.4, 0.0, 0.5, 2.0), atol=1e-12)
    assert_allclose(odom.twist, [0.4, 0.0, 0.5])
    assert odom.distance_m == pytest.approx(0.8)


def test_wheel_odometry_from_ticks_handles_counter_wraparound():
    base = Mecanum(0.05, 0.1, 0.1)
    ticks_per_rev = 4096
    odom = WheelOdometry(base, ticks_per_revolution=ticks_per_rev)
    wheel_rate = np.array(base.inverse(0.3, 0.1, 0.2))  # rad/s
    start = np.array([2**31 - 1000] * 4, dtype=np.int64)  # near the int32 limit: will wrap
    dt = 0.02
    angle = np.zeros(4)
    for i in range(101):
        ticks = start + np.round(angle / (2 * math.pi) * ticks_per_rev).astype(np.int64)
        wrapped = ((ticks + 2**31) % 2**32) - 2**31
        odom.update_from_ticks(wrapped, i * dt)
        angle = angle + wheel_rate * dt
    assert_allclose(odom.pose, closed_form([0, 0, 0], 0.3, 0.1, 0.2, 2.0), atol=2e-3)
    assert_allclose(odom.twist, [0.3, 0.1, 0.2], atol=0.05)


def test_tick_delta_wraps_signed_32_bit():
    assert tick_delta([-(2**31) + 5], [2**31 - 5]).tolist() == [10]
    assert tick_delta([2**31 - 5], [-(2**31) + 5]).tolist() == [-10]


def test_covariance_grows_with_distance_and_not_standing_still():
    odom = WheelOdometry(DiffDrive(0.05, 0.3))
    traces = []
    for _ in range(20):
        odom.update_from_wheel_speeds([10.0, 10.0], 0.1)
        traces.append(np.trace(odom.covariance))
    assert all(b > a for a, b in zip(traces, traces[1:]))
    before = odom.covariance.copy()
    odom.update_from_wheel_speeds([0.0, 0.0], 0.1)
    assert_allclose(odom.covariance, before)
    assert np.all(np.linalg.eigvalsh(odom.covariance) >= -1e-15)


def test_ticks_without_resolution_raises():
    with pytest.raises(ValueError, match=r"^update_from_ticks needs ticks_per_revolution"):
        WheelOdometry(DiffDrive(0.05, 0.3)).update_from_ticks([0, 0], 0.0)
