"""The numba EKF core against filterpy's ExtendedKalmanFilter on robot_localization's model."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from aiorobot.fusion import Ekf
from aiorobot.fusion._kernels import transfer

filterpy_kalman = pytest.importorskip("filterpy.kalman")


def _wrap(a):
    return (a + np.pi) % (2 * np.pi) - np.pi


def _filterpy_twin(ekf: Ekf):
    f = filterpy_kalman.ExtendedKalmanFilter(dim_x=15, dim_z=1)
    f.x = ekf.state.reshape(15, 1).copy()
    f.P = ekf.covariance.copy()
    return f


def _fp_predict(f, Q, dt):
    T = np.zeros((15, 15))
    J = np.zeros((15, 15))
    transfer(f.x.reshape(-1).copy(), dt, T, J)
    f.F = J
    f.Q = Q * dt
    f.predict_x = lambda u=0: None
    f.x = T @ f.x
    f.x[3:6] = _wrap(f.x[3:6])
    f.predict()


def _fp_update(f, z, R, mask):
    idx = np.flatnonzero(mask)
    H = np.zeros((idx.size, 15))
    H[np.arange(idx.size), idx] = 1.0

    def residual(a, b):
        r = a - b
        for row, i in enumerate(idx):
            if 3 <= i <= 5:
                r[row] = _wrap(r[row])
        return r

    f.update(z[idx].reshape(-1, 1), lambda x: H, lambda x: H @ x, R[np.ix_(idx, idx)], residual=residual)
    f.x[3:6] = _wrap(f.x[3:6])


def test_core_matches_filterpy_extended_kalman_filter_to_1e_9():
    rng = np.random.default_rng(7)
    ekf = Ekf(initial_covariance=np.eye(15) * 0.5, initial_state=rng.normal(0, 0.3, 15))
    fp = _filterpy_twin(ekf)
    masks = [
        np.isin(np.arange(15), [0, 1, 5, 6, 7, 11]),  # odometry pose + twist
        np.isin(np.arange(15), [3, 4, 5, 9, 10, 11, 12, 13, 14]),  # imu
        np.isin(np.arange(15), [0, 1, 2, 3, 4, 5]),  # pose fix
        np.isin(np.arange(15), [6, 7, 8, 9, 10, 11]),  # twist
    ]
    for step in range(300):
        dt = float(rng.uniform(0.001, 0.05))
        ekf.predict(dt)
        _fp_predict(fp, ekf.process_noise, dt)
        mask = masks[step % len(masks)]
        z = ekf.state + rng.normal(0, 0.2, 15)
        z[5] = _wrap(z[5] + np.pi * (step % 7 == 0))  # a big yaw innovation across the wrap
        A = rng.normal(0, 0.1, (15, 15))
        R = A @ A.T + np.eye(15) * 0.01
        result = ekf.update(z, R, mask)
        assert result.accepted
        _fp_update(fp, z, R, mask)
        np.testing.assert_allclose(ekf.state, fp.x.reshape(-1), rtol=0, atol=1e-9)
        np.testing.assert_allclose(ekf.covariance, fp.P, rtol=0, atol=1e-9)


def test_mahalanobis_threshold_rejects_and_leaves_state_untouched():
    ekf = Ekf(initial_covariance=np.eye(15) * 0.01)
    mask = np.zeros(15, bool)
    mask[:2] = True
    z = np.zeros(15)
    z[0] = 2.0
    before = ekf.snapshot()
    result = ekf.update(z, np.eye(15) * 0.0025, mask, mahalanobis_threshold=3.0)
    assert not result.accepted
    assert result.mahalanobis_sq == pytest.approx(4.0 / (0.01 + 0.0025))
    np.testing.assert_array_equal(ekf.state, before[0])
    np.testing.assert_array_equal(ekf.covariance, before[1])
    z[0] = 0.1
    assert ekf.update(z, np.eye(15) * 0.0025, mask, mahalanobis_threshold=3.0).accepted


def test_nan_member_is_left_out_like_robot_localization():
    ekf = Ekf(initial_covariance=np.eye(15))
    z = np.zeros(15)
    z[0], z[1] = 1.0, np.nan
    mask = np.zeros(15, bool)
    mask[:2] = True
    assert ekf.update(z, np.eye(15), mask).accepted
    assert ekf.state[0] == pytest.approx(0.5)
    assert ekf.state[1] == 0.0
    assert np.all(np.isfinite(ekf.covariance))


def test_importing_fusion_does_not_import_filterpy_or_numba():
    code = "import sys, aiorobot.fusion; print('filterpy' in sys.modules, 'numba' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.split() == ["False", "False"]
