"""ComplementaryEstimator: gyro integration, dt clamp, accelerometer roll/pitch, odometry yaw blend."""

from __future__ import annotations

import math

import pytest

from aiorobot.fusion import ComplementaryEstimator


def test_first_sample_has_zero_dt_and_gyro_integrates_after():
    f = ComplementaryEstimator(alpha=1.0)
    assert f.step(5.0, 0.0, 0.0, 1.0, 0.0, 0.0, 9.81) == (0.0, 0.0, 0.0)
    assert f.step(5.05, 0.0, 0.0, 1.0, 0.0, 0.0, 9.81)[2] == pytest.approx(0.05)


def test_dt_is_clamped_to_0_1_s_and_backwards_stamps_integrate_nothing():
    f = ComplementaryEstimator(alpha=1.0)
    f.step(0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 9.81)
    assert f.step(3.0, 0.0, 0.0, 1.0, 0.0, 0.0, 9.81)[2] == pytest.approx(0.1)
    assert f.step(2.0, 0.0, 0.0, 1.0, 0.0, 0.0, 9.81)[2] == pytest.approx(0.1)


def test_odometry_yaw_pulls_by_one_minus_alpha_across_the_wrap():
    f = ComplementaryEstimator(alpha=0.98)
    f.yaw = 3.1
    f.set_odometry_yaw(-3.1)  # 0.083 rad away across +-pi
    f.step(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 9.81)
    expected = 3.1 + 0.02 * (2 * math.pi - 6.2)
    assert f.yaw == pytest.approx(expected)


def test_accelerometer_levels_roll_and_pitch_and_a_gyro_bias_stays_bounded():
    f = ComplementaryEstimator(alpha=0.98)
    g = 9.81
    roll_true = 0.2
    for k in range(2000):  # 20 s at 100 Hz, gyro x biased by 0.05 rad/s
        f.step(0.01 * k, 0.05, 0.0, 0.0, 0.0, g * math.sin(roll_true), g * math.cos(roll_true))
    # steady state: bias * dt * alpha / (1 - alpha) = 0.05 * 0.01 * 49
    assert f.roll == pytest.approx(roll_true + 0.05 * 0.01 * 0.98 / 0.02, abs=1e-6)
    assert f.pitch == pytest.approx(0.0, abs=1e-9)


def test_nan_sample_is_skipped_and_counted():
    f = ComplementaryEstimator()
    f.step(0.0, 0.0, 0.0, 0.1, 0.0, 0.0, 9.81)
    assert f.step(0.01, math.nan, 0.0, 0.1, 0.0, 0.0, 9.81) == (f.roll, f.pitch, f.yaw)
    assert f.rejected == 1
    assert all(math.isfinite(v) for v in (f.roll, f.pitch, f.yaw))


def test_alpha_outside_0_1_is_refused():
    with pytest.raises(ValueError, match=r"^alpha: expected a value in \[0, 1\], got 1.5$"):
        ComplementaryEstimator(1.5)
