"""Stamp-ordered application, rewind-and-replay, and accuracy on a seeded figure-eight."""

from __future__ import annotations

import math

import numpy as np
import pytest

from aiorobot.fusion import Ekf, FilterTimeline, Measurement
from aiorobot.fusion._synthetic import figure_eight, fuse_figure_eight


def _wrap(a):
    return (a + np.pi) % (2 * np.pi) - np.pi


def _m(stamp, source, values, var=1e-2, threshold=math.inf):
    z = np.zeros(15)
    mask = np.zeros(15, bool)
    for i, v in values.items():
        z[i] = v
        mask[i] = True
    return Measurement(stamp, source, z, np.eye(15) * var, mask, threshold)


def _stream(seed=3, n=60):
    rng = np.random.default_rng(seed)
    out = []
    for k in range(n):
        t = 0.02 * k
        out.append(_m(t, "odom0", {6: 0.5 + rng.normal(0, 0.01), 11: 0.2 + rng.normal(0, 0.01)}))
        if k % 10 == 5:
            out.append(_m(t + 0.001, "pose0", {0: 0.5 * t + rng.normal(0, 0.02), 1: rng.normal(0, 0.02)}, var=4e-4))
    return out


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_fused_heading_beats_wheel_odometry_fourfold_over_a_figure_eight(seed):
    data = figure_eight(seed)
    run = fuse_figure_eight(data, use_fixes=False)
    fused = abs(_wrap(run.estimate[-1, 2] - data.truth[-1, 2]))
    odom_only = abs(_wrap(data.odom_pose[-1, 2] - data.truth[-1, 2]))
    assert fused <= odom_only / 4


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_pose_fixes_give_5cm_rmse_and_every_2m_outlier_is_rejected(seed):
    data = figure_eight(seed)
    run = fuse_figure_eight(data)
    error = np.hypot(*(run.estimate[:, :2] - data.truth[:, :2]).T)
    assert np.sqrt(np.mean(error**2)) <= 0.05
    rejected = ~np.asarray(run.fix_results)
    np.testing.assert_array_equal(rejected, data.outlier)
    assert run.timeline.rejected[("pose0", "Mahalanobis distance over the rejection threshold")] == data.outlier.sum()


def test_lagged_measurement_rewinds_and_replays_to_the_in_order_result():
    stream = _stream()
    in_order = FilterTimeline(Ekf(), smooth_lagged_data=True, history_length_sec=1.0)
    for m in sorted(stream, key=lambda m: m.stamp_sec):
        in_order.process(m)
    lagged = FilterTimeline(Ekf(), smooth_lagged_data=True, history_length_sec=1.0)
    # every pose fix arrives 0.1 s late, after the odometry that followed it
    late = sorted(stream, key=lambda m: m.stamp_sec + (0.1 if m.source == "pose0" else 0.0))
    for m in late:
        assert lagged.process(m).accepted
    assert lagged.replays == sum(m.source == "pose0" for m in stream)
    np.testing.assert_allclose(lagged.ekf.state, in_order.ekf.state, atol=1e-12)
    np.testing.assert_allclose(lagged.ekf.covariance, in_order.ekf.covariance, atol=1e-12)
    assert lagged.accepted == in_order.accepted


def test_lagged_measurement_without_smoothing_is_rejected_not_applied_out_of_order():
    timeline = FilterTimeline(Ekf())
    timeline.process(_m(1.0, "odom0", {6: 1.0}))
    timeline.process(_m(2.0, "odom0", {6: 1.0}))
    before = timeline.ekf.snapshot()
    result = timeline.process(_m(1.5, "pose0", {0: 5.0}))
    assert not result.accepted
    np.testing.assert_array_equal(timeline.ekf.state, before[0])
    assert timeline.rejected[("pose0", "older than the last update (smooth_lagged_data is false)")] == 1


def test_measurement_older_than_history_length_is_rejected():
    timeline = FilterTimeline(Ekf(), smooth_lagged_data=True, history_length_sec=0.5)
    for k in range(30):
        timeline.process(_m(0.1 * k, "odom0", {6: 1.0}))
    before = timeline.ekf.snapshot()
    assert not timeline.process(_m(1.0, "pose0", {0: 5.0})).accepted
    np.testing.assert_array_equal(timeline.ekf.state, before[0])
    assert timeline.rejected[("pose0", "older than history_length")] == 1
    assert timeline.process(_m(2.75, "pose0", {0: 2.7})).accepted


def test_two_d_mode_holds_z_roll_pitch_at_zero():
    timeline = FilterTimeline(Ekf(), two_d_mode=True)
    for k in range(50):
        timeline.process(_m(0.02 * k, "odom0", {2: 3.0, 3: 0.4, 6: 1.0, 8: 2.0}))
    assert np.all(np.abs(timeline.ekf.state[[2, 3, 4, 8, 9, 10, 14]]) < 1e-3)
    assert timeline.ekf.state[6] == pytest.approx(1.0, abs=1e-3)
