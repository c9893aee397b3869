"""The numba UKF core against filterpy's unscented transform, and UkfNode on the EKF's timeline and topics."""

from __future__ import annotations

import asyncio
import math

import numpy as np
import pytest

from aiorobot import Node, Runtime
from aiorobot.fusion import FilterTimeline, Measurement, Ukf, UkfNode
from aiorobot.fusion._kernels import transfer
from aiorobot.msgs.nav_msgs import Odometry

filterpy_kalman = pytest.importorskip("filterpy.kalman")

ANGLES = [3, 4, 5]


def _wrap(a):
    return (a + np.pi) % (2 * np.pi) - np.pi


def _fx(x, dt):
    T = np.zeros((15, 15))
    transfer(x.copy(), dt, T, np.zeros((15, 15)))
    return T @ x


def _x_mean(sigmas, wm):
    x = wm @ sigmas
    for i in ANGLES:
        x[i] = math.atan2(wm @ np.sin(sigmas[:, i]), wm @ np.cos(sigmas[:, i]))
    return x


def _residual_x(a, b):
    d = a - b
    d[ANGLES] = _wrap(d[ANGLES])
    return d


def _oracle(ukf: Ukf, alpha, beta, kappa):
    points = filterpy_kalman.MerweScaledSigmaPoints(15, alpha=alpha, beta=beta, kappa=kappa)
    f = filterpy_kalman.UnscentedKalmanFilter(
        dim_x=15, dim_z=1, dt=0.0, hx=None, fx=_fx, points=points, x_mean_fn=_x_mean, residual_x=_residual_x
    )
    f.x = ukf.state.copy()
    f.P = ukf.covariance.copy()
    return f


def _oracle_update(f, z, R, mask, fresh_sigmas):
    """ukf.cpp's correct through filterpy: its update, then ukf.cpp's ``P -= K P_zz K^T`` (filterpy
    subtracts ``K (P_zz + R) K^T``: add ``K R K^T`` back) and the state's angles wrapped."""
    idx = np.flatnonzero(mask)
    angles = [k for k, i in enumerate(idx) if i in ANGLES]

    def z_mean(sigmas, wm):
        out = wm @ sigmas
        for k in angles:
            out[k] = math.atan2(wm @ np.sin(sigmas[:, k]), wm @ np.cos(sigmas[:, k]))
        return out

    def residual_z(a, b):
        d = np.asarray(a, dtype=float) - b
        d[angles] = _wrap(d[angles])
        return d

    if fresh_sigmas:  # ukf.cpp draws new sigma points for a correction that follows a correction
        f.sigmas_f = f.points_fn.sigma_points(f.x, f.P)
    f.z_mean, f.residual_z = z_mean, residual_z
    Rs = R[np.ix_(idx, idx)]
    f.update(z[idx], R=Rs, hx=lambda x: x[idx])
    f.P = f.P + f.K @ Rs @ f.K.T
    f.x[ANGLES] = _wrap(f.x[ANGLES])


@pytest.mark.parametrize(("alpha", "beta", "kappa"), [(0.001, 2.0, 0.0), (0.3, 2.0, 1.0)])
def test_sigma_points_and_weights_are_filterpys_merwe_points(alpha, beta, kappa):
    rng = np.random.default_rng(1)
    A = rng.normal(size=(15, 15))
    ukf = Ukf(initial_covariance=A @ A.T * 0.01 + np.eye(15) * 0.1, initial_state=rng.normal(size=15), alpha=alpha,
              beta=beta, kappa=kappa)  # fmt: skip
    points = filterpy_kalman.MerweScaledSigmaPoints(15, alpha=alpha, beta=beta, kappa=kappa)
    np.testing.assert_allclose(ukf.mean_weights, points.Wm, rtol=1e-12)
    np.testing.assert_allclose(ukf.covariance_weights, points.Wc, rtol=1e-12)
    from aiorobot.fusion._ukf_kernels import sigma_points_inplace

    sigmas, L = np.zeros((31, 15)), np.zeros((15, 15))
    assert sigma_points_inplace(ukf.state, ukf.covariance, ukf.scale, sigmas, L)
    np.testing.assert_allclose(sigmas, points.sigma_points(ukf.state, ukf.covariance), rtol=0, atol=1e-12)


@pytest.mark.parametrize(("alpha", "beta", "kappa"), [(0.001, 2.0, 0.0), (0.3, 2.0, 1.0)])
def test_predict_and_correct_equal_the_unscented_transform_over_random_steps(alpha, beta, kappa):
    rng = np.random.default_rng(7)
    state = rng.normal(scale=0.5, size=15)
    state[5] = 3.1  # near the wrap
    Q = np.diag(rng.uniform(0.01, 0.1, 15))
    ukf = Ukf(process_noise=Q, initial_covariance=np.eye(15) * 0.05, initial_state=state, alpha=alpha, beta=beta,
              kappa=kappa)  # fmt: skip
    f = _oracle(ukf, alpha, beta, kappa)
    corrected = False
    for step in range(120):
        if step % 3 != 2:
            dt = rng.uniform(0.01, 0.1)
            ukf.predict(dt)
            prior = f.points_fn.sigma_points(f.x, f.P)
            f.Q = Q * dt
            f.predict(dt=dt)
            f.x[ANGLES] = _wrap(f.x[ANGLES])
            # filterpy then draws new points from the predicted (x, P); ukf.cpp corrects with the moved ones
            f.sigmas_f = np.array([_fx(p, dt) for p in prior])
            corrected = False
        mask = rng.random(15) < 0.4
        mask[rng.integers(15)] = True
        z = ukf.state + rng.normal(scale=0.05, size=15)
        z[ANGLES] = _wrap(z[ANGLES])
        B = rng.normal(size=(15, 15)) * 0.02
        R = B @ B.T + np.eye(15) * 0.01
        result = ukf.update(z, R, mask)
        assert result.accepted
        _oracle_update(f, z, R, mask, fresh_sigmas=corrected)
        corrected = True
        np.testing.assert_allclose(ukf.state, f.x, rtol=0, atol=1e-7)
        np.testing.assert_allclose(ukf.covariance, f.P, rtol=0, atol=1e-7)


def test_mahalanobis_threshold_and_bad_measurements_as_the_ekf():
    ukf = Ukf(initial_covariance=np.eye(15) * 0.01)
    ukf.predict(0.1)
    before = ukf.snapshot()
    z = np.zeros(15)
    z[0] = 5.0
    rejected = ukf.update(z, np.eye(15) * 0.01, np.eye(15, dtype=bool)[0], mahalanobis_threshold=3.0)
    assert not rejected.accepted and rejected.reason == "Mahalanobis distance over the rejection threshold"
    assert np.array_equal(ukf.state, before[0]) and np.array_equal(ukf.covariance, before[1])
    z[0] = math.nan
    assert ukf.update(z, np.eye(15), np.eye(15, dtype=bool)[0]).reason == "no finite member selected"


@pytest.mark.parametrize(("alpha", "kappa", "message"), [
    (0.0, 0.0, "alpha: expected a non-zero spread"), (0.001, -15.0, "kappa: expected a value above -15"),
    (math.nan, 0.0, "alpha: expected a finite number"),
])  # fmt: skip
def test_constants_that_give_no_spread_are_refused(alpha, kappa, message):
    with pytest.raises(ValueError, match=message):
        Ukf(alpha=alpha, kappa=kappa)


def test_robot_localization_ukf_measurements_case():
    # robot_localization test/test_ukf.cpp UkfTest.Measurements: the first measurement initialises
    # the filter; with the covariance set to 0.5 I, a second one at twice the values, 1 ns later and
    # with variance 1e-9, pulls every member to within 1e-3 of it
    ukf = Ukf()
    timeline = FilterTimeline(ukf)
    measurement = np.arange(15) * 0.01 * 15
    cov = np.eye(15) * 1e-9
    timeline.process(Measurement(1000e-9, "odom0", measurement, cov, np.ones(15, bool)))
    assert np.array_equal(ukf.state, measurement) and np.array_equal(ukf.covariance, cov)
    ukf.covariance[:] = np.eye(15) * 0.5
    assert timeline.process(Measurement(1002e-9, "odom0", measurement * 2, cov, np.ones(15, bool))).accepted
    assert np.all(np.abs(measurement * 2 - ukf.state) < 1e-3)


async def test_ukf_node_fuses_odometry_on_the_ekf_topics():
    async with Runtime() as rt:
        probe = rt.add_node(Node("probe"))
        odom_pub = probe.create_publisher(Odometry, "/odom", 50)
        filtered: list[Odometry] = []
        probe.create_subscription(Odometry, "odometry/filtered", filtered.append, 100)
        ukf = rt.add_node(UkfNode(parameter_overrides={
            "two_d_mode": True, "odom0": "/odom", "odom0_queue_size": 50, "alpha": 0.001, "kappa": 0.0, "beta": 2.0,
            "odom0_config": [False] * 6 + [True, True, False, False, False, True] + [False] * 3,
        }), executor="priority")  # fmt: skip
        assert isinstance(ukf.filter, Ukf) and ukf.get_parameter("alpha").value == 0.001
        t0 = rt.now().nanoseconds * 1e-9
        for k in range(10):
            msg = Odometry()
            stamp = t0 + 0.02 * k
            msg.header.stamp.sec, msg.header.stamp.nanosec = int(stamp), int((stamp % 1) * 1e9)
            msg.header.frame_id, msg.child_frame_id = "odom", "base_link"
            msg.twist.twist.linear.x = 0.5
            msg.twist.covariance = (np.eye(6) * 1e-4).reshape(36)
            odom_pub.publish(msg)
        async with asyncio.timeout(30):
            while len(filtered) < 10:
                await asyncio.sleep(0.005)
        last = filtered[-1]
        assert last.twist.twist.linear.x == pytest.approx(0.5, abs=1e-3)
        assert last.pose.pose.position.x == pytest.approx(0.5 * 0.18, abs=5e-3)
        assert (last.header.frame_id, last.child_frame_id) == ("odom", "base_link")
