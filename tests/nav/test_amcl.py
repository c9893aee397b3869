"""AMCL on a known map: converges from a wrong initial pose; deterministic for a seed; bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest

from aiorobot.nav._amcl import Amcl, AmclParameters, likelihood_field

RES = 0.05


def _box_world() -> tuple[np.ndarray, tuple[float, float]]:
    """The sim's `box`: walls with inner faces at +-3 m, plus a pillar to break the symmetry."""
    n = int(6.4 / RES)
    occ = np.zeros((n, n), dtype=bool)
    occ[:4, :] = occ[-4:, :] = occ[:, :4] = occ[:, -4:] = True
    occ[80:90, 30:36] = True  # pillar near (-1.5, 0.9)
    return occ, (-3.2, -3.2)


def _scan(occ: np.ndarray, origin: tuple[float, float], pose: tuple[float, float, float], beams: int = 180,
          range_max: float = 12.0, rng: np.random.Generator | None = None) -> tuple[np.ndarray, float, float]:
    """A test oracle: march each ray through the grid (1 cm steps)."""
    angle_min, inc = -math.pi, 2 * math.pi / beams
    ranges = np.full(beams, range_max)
    steps = np.arange(0.0, range_max, 0.01)
    for i in range(beams):
        a = pose[2] + angle_min + i * inc
        xs = pose[0] + steps * math.cos(a)
        ys = pose[1] + steps * math.sin(a)
        c = np.floor((xs - origin[0]) / RES).astype(int)
        r = np.floor((ys - origin[1]) / RES).astype(int)
        inside = (r >= 0) & (c >= 0) & (r < occ.shape[0]) & (c < occ.shape[1])
        hit = np.zeros_like(inside)
        hit[inside] = occ[r[inside], c[inside]]
        if hit.any():
            ranges[i] = steps[np.argmax(hit)]
    if rng is not None:
        ranges = ranges + rng.normal(0, 0.01, beams)
    return ranges, angle_min, inc


def _run(seed: int) -> tuple[Amcl, tuple[float, float, float]]:
    occ, origin = _box_world()
    amcl = Amcl(occ, RES, origin, AmclParameters(min_particles=300, max_particles=1000, update_min_d=0.1, update_min_a=0.1), seed=seed)
    truth = [0.0, 0.0, 0.0]
    amcl.set_initial_pose(truth[0] + 0.4, truth[1] - 0.3, truth[2] + 0.25)
    noise = np.random.default_rng(seed + 100)
    amcl.update(tuple(truth), *_scan(occ, origin, tuple(truth), rng=noise))
    for _ in range(25):  # drive a gentle arc: 0.15 m and 0.1 rad per step
        truth[0] += 0.15 * math.cos(truth[2])
        truth[1] += 0.15 * math.sin(truth[2])
        truth[2] += 0.1
        amcl.update(tuple(truth), *_scan(occ, origin, tuple(truth), rng=noise))
    return amcl, tuple(truth)  # type: ignore[return-value]


def test_converges_from_a_wrong_initial_pose_within_25_updates() -> None:
    amcl, truth = _run(seed=3)
    x, y, yaw = amcl.pose
    assert math.hypot(x - truth[0], y - truth[1]) < 0.08
    assert abs((yaw - truth[2] + math.pi) % (2 * math.pi) - math.pi) < 0.05
    cov = amcl.covariance
    assert cov[0, 0] < 0.25 / 4 and cov[1, 1] < 0.25 / 4  # far tighter than the initial 0.25 m²
    assert len(amcl) < 1000  # KLD shrank the particle set


def test_same_seed_same_estimate() -> None:
    assert _run(seed=5)[0].pose == _run(seed=5)[0].pose


def test_likelihood_field_is_distance_to_the_nearest_occupied_cell_clipped() -> None:
    occ = np.zeros((20, 20), dtype=bool)
    occ[10, 10] = True
    f = likelihood_field(occ, 0.1, 0.5)
    assert f[10, 10] == 0.0
    assert f[10, 13] == pytest.approx(0.3)
    assert f[0, 0] == 0.5


def test_bad_parameters_and_missing_initial_pose_are_clear_errors() -> None:
    with pytest.raises(ValueError, match="robot_model_type: expected 'differential' or 'omnidirectional', found 'tank'"):
        AmclParameters(robot_model_type="tank")
    occ, origin = _box_world()
    amcl = Amcl(occ, RES, origin)
    with pytest.raises(RuntimeError, match="no initial pose"):
        amcl.update((0, 0, 0), np.ones(10), -math.pi, 0.1)


def test_omnidirectional_motion_model_tracks_sideways_motion() -> None:
    occ, origin = _box_world()
    amcl = Amcl(occ, RES, origin, AmclParameters(robot_model_type="omnidirectional", min_particles=300, max_particles=800,
                                                 update_min_d=0.05), seed=2)
    truth = [0.0, -1.0, 0.0]
    amcl.set_initial_pose(*truth, cov_xx=0.01, cov_yy=0.01, cov_aa=0.005)
    noise = np.random.default_rng(9)
    amcl.update(tuple(truth), *_scan(occ, origin, tuple(truth), rng=noise))
    for _ in range(15):  # strafe left (mecanum), heading unchanged
        truth[1] += 0.1
        amcl.update(tuple(truth), *_scan(occ, origin, tuple(truth), rng=noise))
    x, y, _ = amcl.pose
    assert math.hypot(x - truth[0], y - truth[1]) < 0.08
