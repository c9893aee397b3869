from __future__ import annotations

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

from aiorobot.control import DiffDrive, Mecanum, saturate_wheel_speeds


def test_diff_drive_known_values():
    drive = DiffDrive(wheel_radius=0.1, wheel_separation=0.5)
    assert drive.inverse(1.0, 0.0) == pytest.approx((10.0, 10.0))
    # turning on the spot at 1 rad/s: each wheel moves 0.25 m/s -> 2.5 rad/s
    assert drive.inverse(0.0, 1.0) == pytest.approx((-2.5, 2.5))
    assert drive.forward(-2.5, 2.5) == pytest.approx((0.0, 1.0))


def test_diff_drive_forward_of_inverse_is_identity_vectorised():
    rng = np.random.default_rng(1)
    drive = DiffDrive(0.033, 0.16)
    v, omega = rng.normal(size=(2, 100))
    v_back, omega_back = drive.forward(*drive.inverse(v, omega))
    assert_allclose(v_back, v)
    assert_allclose(omega_back, omega)


def test_mecanum_known_values_follow_the_issue_formulas():
    base = Mecanum(wheel_radius=0.05, half_length=0.2, half_width=0.15)
    k, r = 0.35, 0.05
    vx, vy, om = 0.3, -0.2, 0.5
    expected = ((vx - vy - k * om) / r, (vx + vy + k * om) / r, (vx + vy - k * om) / r, (vx - vy + k * om) / r)
    assert base.inverse(vx, vy, om) == pytest.approx(expected)
    # pure sideways motion to the left: fl and rr spin backward, fr and rl forward
    assert base.inverse(0.0, 1.0, 0.0) == pytest.approx((-20.0, 20.0, 20.0, -20.0))


def test_mecanum_forward_of_inverse_is_identity():
    rng = np.random.default_rng(2)
    base = Mecanum(0.04, 0.1, 0.12)
    twists = rng.normal(size=(50, 3))
    assert_allclose(base.body_twist(base.wheel_speeds(twists)), twists, atol=1e-12)
    vx, vy, om = base.forward(*base.inverse(*twists.T))
    assert_allclose(np.stack([vx, vy, om], axis=1), twists, atol=1e-12)


def test_mecanum_forward_is_least_squares_for_inconsistent_wheels():
    base = Mecanum(0.05, 0.2, 0.15)
    wheels = np.array([1.0, 2.0, 0.5, -0.3])
    lstsq = np.linalg.lstsq(base._wheels_from_twist, wheels, rcond=None)[0]
    assert_allclose(base.forward(*wheels), lstsq)


def test_diff_drive_body_twist_roundtrip_ignores_lateral_speed():
    drive = DiffDrive(0.1, 0.4)
    wheels = drive.wheel_speeds([0.5, 9.0, -0.2])
    assert_allclose(drive.body_twist(wheels), [0.5, 0.0, -0.2])


@pytest.mark.parametrize(
    ("make", "message"),
    [
        (lambda: DiffDrive(0.0, 0.3), r"^wheel_radius must be a finite number > 0, got 0\.0; pass a positive value$"),
        (lambda: DiffDrive(0.1, -0.3), r"^wheel_separation must be a finite number > 0, got -0\.3"),
        (lambda: Mecanum(-0.05, 0.1, 0.1), r"^wheel_radius must be a finite number > 0, got -0\.05"),
        (lambda: Mecanum(0.05, 0.0, 0.0), r"^half_length \+ half_width must be > 0, got 0\.0 \+ 0\.0"),
        (lambda: Mecanum(0.05, -0.1, 0.2), r"^half_length must be a finite number >= 0, got -0\.1$"),
    ],
)
def test_invalid_geometry_raises_with_expected_and_got(make, message):
    with pytest.raises(ValueError, match=message):
        make()


def test_wrong_twist_shape_names_expected_and_received_shape():
    with pytest.raises(ValueError, match=r"^body_twist must have shape \(\.\.\., 3\) as \(vx, vy, omega\), got shape \(2,\)$"):
        Mecanum(0.05, 0.1, 0.1).wheel_speeds([1.0, 2.0])


def test_saturation_keeps_direction_of_motion():
    base = Mecanum(0.05, 0.2, 0.15)
    twist = np.array([1.0, 0.6, 1.2])
    wheels = base.wheel_speeds(twist)
    limited = saturate_wheel_speeds(wheels, 10.0)
    assert np.max(np.abs(limited)) == pytest.approx(10.0)
    achieved = base.body_twist(limited)
    scale = achieved[0] / twist[0]
    assert 0.0 < scale < 1.0
    assert_allclose(achieved, scale * twist)


def test_saturation_leaves_feasible_commands_alone_and_handles_rows():
    wheels = np.array([[1.0, -2.0], [30.0, -60.0], [0.0, 0.0]])
    limited = saturate_wheel_speeds(wheels, 5.0)
    assert_allclose(limited[0], [1.0, -2.0])
    assert_allclose(limited[1], [2.5, -5.0])
    assert_allclose(limited[2], [0.0, 0.0])


def test_saturation_rejects_non_positive_limit():
    with pytest.raises(ValueError, match=r"^max_wheel_speed must be a finite number > 0, got 0"):
        saturate_wheel_speeds([1.0, 2.0], 0)
    assert math.isfinite(saturate_wheel_speeds([1.0], 1.0)[0])
