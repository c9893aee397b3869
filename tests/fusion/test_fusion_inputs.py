"""robot_localization input handling: _config, _differential, _relative, gravity removal, covariance checks."""

from __future__ import annotations

import math

import numpy as np
import pytest

from aiorobot.fusion._inputs import (
    InputConfig,
    InputRejected,
    PoseTracker,
    check_message_covariance,
    imu_measurements,
    pose_measurement,
)


def _cfg(kind, members, **kw):
    config = np.zeros(15, bool)
    config[members] = True
    return InputConfig(f"{kind}0", kind, "/t", config, **kw)


def _q(yaw):
    return np.array([0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2)])


def test_absolute_pose_fills_the_selected_members_with_the_message_covariance():
    cov = np.diag([0.1, 0.2, 0.3, 0.4, 0.5, 0.6])
    m = pose_measurement(_cfg("pose", [0, 1, 5]), PoseTracker(), 1.0, np.array([1.0, 2.0, 3.0]), _q(0.5), cov.reshape(36))
    assert list(np.flatnonzero(m.mask)) == [0, 1, 5]
    np.testing.assert_allclose(m.z[[0, 1, 5]], [1.0, 2.0, 0.5])
    np.testing.assert_allclose(m.covariance[:6, :6], cov)


def test_relative_pose_is_taken_from_the_first_one():
    cfg = _cfg("pose", [0, 1, 5], relative=True)
    tracker = PoseTracker()
    cov = (np.eye(6) * 0.01).reshape(36)
    first = pose_measurement(cfg, tracker, 0.0, np.array([5.0, 5.0, 0.0]), _q(math.pi / 2), cov)
    np.testing.assert_allclose(first.z[[0, 1, 5]], 0.0, atol=1e-12)
    m = pose_measurement(cfg, tracker, 1.0, np.array([5.0, 6.0, 0.0]), _q(math.pi / 2), cov)
    np.testing.assert_allclose(m.z[[0, 1, 5]], [1.0, 0.0, 0.0], atol=1e-12)  # 1 m ahead in the first pose's frame


def test_differential_pose_becomes_a_body_velocity():
    cfg = _cfg("odom", [0, 1, 5], differential=True)
    tracker = PoseTracker()
    cov = (np.eye(6) * 0.01).reshape(36)
    assert pose_measurement(cfg, tracker, 0.0, np.array([0.0, 0.0, 0.0]), _q(math.pi / 2), cov) is None
    m = pose_measurement(cfg, tracker, 0.5, np.array([0.0, 1.0, 0.0]), _q(math.pi / 2 + 0.1), cov)
    assert list(np.flatnonzero(m.mask)) == [6, 7, 11]
    np.testing.assert_allclose(m.z[[6, 7, 11]], [2.0, 0.0, 0.2], atol=1e-12)
    assert m.covariance[6, 6] == pytest.approx(0.02 / 0.25)


def test_imu_gravity_is_removed_through_the_orientation():
    cfg = _cfg("imu", [5, 11, 12, 13, 14], remove_gravitational_acceleration=True)
    roll = 0.3
    q = np.array([math.sin(roll / 2), 0.0, 0.0, math.cos(roll / 2)])
    g = 9.80665
    accel = np.array([0.5, g * math.sin(roll), g * math.cos(roll)])  # 0.5 m/s^2 forward, tilted by roll
    cov3 = (np.eye(3) * 1e-3).reshape(9)
    out = imu_measurements(cfg, PoseTracker(), 1.0, q, cov3, np.array([0.0, 0.0, 0.2]), cov3, accel, cov3)
    by_source = {m.source: m for m in out}
    np.testing.assert_allclose(by_source["imu0_acceleration"].z[12:15], [0.5, 0.0, 0.0], atol=1e-9)
    assert by_source["imu0_twist"].z[11] == pytest.approx(0.2)
    assert by_source["imu0_pose"].mask[5] and not by_source["imu0_pose"].mask[3]


def test_imu_in_another_frame_is_rotated_into_the_base_frame():
    cfg = _cfg("imu", [11])
    base_from_imu = np.array([[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, -1.0]])  # mounted upside down
    cov3 = (np.eye(3) * 1e-3).reshape(9)
    (m,) = imu_measurements(cfg, PoseTracker(), 1.0, _q(0.0), cov3, np.array([0.0, 0.0, 0.2]), cov3, np.zeros(3), cov3, base_from_imu)
    assert m.z[11] == pytest.approx(-0.2)


@pytest.mark.parametrize(
    ("cov", "reason"),
    [
        (np.full((3, 3), np.nan), "^x covariance has NaN or inf$"),
        (np.array([[1.0, 0.5, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]), "^x covariance is not symmetric$"),
        (np.diag([1.0, -1.0, 1.0]), "^x covariance is not positive semi-definite$"),
    ],
)
def test_message_covariance_must_be_finite_symmetric_psd(cov, reason):
    with pytest.raises(InputRejected, match=reason):
        check_message_covariance("x", cov.reshape(9), 3)
    np.testing.assert_array_equal(check_message_covariance("x", np.zeros(9), 3), np.zeros((3, 3)))
