"""Correlative scan matching of one scan against reference points (pure; kernels in ``_slam_kernels``).

:func:`match` smears the reference points into a likelihood grid around the prior pose, runs the
two-level branch-and-bound search of :func:`~._slam_kernels.search` over the translation and
rotation window, polishes the best pose below a cell and returns a :class:`Match`: the pose,
its response (mean likelihood under the scan's points, 0..1), its covariance (from the
Gauss-Newton normal matrix, so a corridor's long axis comes out uncertain) and, when asked,
the best response found farther than ``ambiguity_radius`` from the winner, the ambiguity test
loop closures must pass.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from . import _slam_kernels as k
from ._slam_graph import wrap

__all__ = ["Match", "match", "scan_points"]

#: covariance floor of a match (m^2, m^2, rad^2): no match is trusted below a centimetre / 0.3 degrees
_MIN_VARIANCE = (1e-4, 1e-4, 3e-5)
#: variance of one point's likelihood value about the model (0.1^2): scales the Gauss-Newton covariance
#: (the sample variance of the residuals would count points in unexplored space, which have no reference, as noise)
_RESPONSE_VARIANCE = 0.01


@dataclass(frozen=True, slots=True)
class Match:
    """A scan match: the pose, its response (0..1), covariance (3, 3), and the search's best and
    runner-up scores on whole cells, the runner-up farther than the ambiguity radius from the best
    (-1 when not searched or nothing was there)."""

    pose: tuple[float, float, float]
    response: float
    covariance: NDArray[np.float64]
    best: float = -1.0
    runner_up: float = -1.0

    @property
    def edge_covariance(self) -> NDArray[np.float64]:
        """The covariance a graph edge takes: :attr:`covariance` plus a floor (1 cm, 0.3 degrees)."""
        return self.covariance + np.diag(_MIN_VARIANCE)

    @property
    def ambiguity(self) -> float:
        """Runner-up score / best score: near 1 when another place fits as well (a corridor)."""
        return max(0.0, self.runner_up) / self.best if self.best > 0 else 1.0


def scan_points(ranges: NDArray[np.float64], angle_min: float, angle_increment: float, range_min: float,
                max_range: float, laser_pose: tuple[float, float, float] = (0.0, 0.0, 0.0)) -> NDArray[np.float64]:
    """The returns of a scan as points (N, 2) in the robot frame: finite, >= range_min, < max_range."""
    r = np.asarray(ranges, dtype=np.float64)
    a = laser_pose[2] + angle_min + np.arange(len(r)) * angle_increment
    ok = np.isfinite(r) & (r >= range_min) & (r < max_range)
    r, a = r[ok], a[ok]
    return np.ascontiguousarray(np.column_stack([laser_pose[0] + r * np.cos(a), laser_pose[1] + r * np.sin(a)]))


def transform_points(pose: tuple[float, float, float] | NDArray[np.float64], points: NDArray[np.float64]) -> NDArray[np.float64]:
    c, s = math.cos(pose[2]), math.sin(pose[2])
    return np.column_stack([pose[0] + c * points[:, 0] - s * points[:, 1], pose[1] + s * points[:, 0] + c * points[:, 1]])


def match(reference: NDArray[np.float64], points: NDArray[np.float64], prior: tuple[float, float, float], *,
          resolution: float, smear_deviation: float, linear_half: float, angular_half: float,
          block: int = 4, ambiguity_radius: float = -1.0) -> Match:
    """Match ``points`` (N, 2, robot frame) against ``reference`` (M, 2, map frame) near ``prior``.

    Searches translations within ``linear_half`` m and rotations within ``angular_half`` rad of the
    prior (rotation step: about a cell at the scan's 90th-percentile range).
    """
    if len(points) == 0 or len(reference) == 0:
        return Match(prior, 0.0, np.diag([1e6, 1e6, 1e6]))
    spread = float(np.percentile(np.hypot(points[:, 0], points[:, 1]), 90))
    step = resolution / max(spread, 4.0 * resolution)
    n_angles = int(math.ceil(angular_half / step))
    thetas = prior[2] + step * np.arange(-n_angles, n_angles + 1)
    half_cells = int(math.ceil(linear_half / resolution))
    margin = linear_half + 3.0 * smear_deviation + resolution
    # the grid covers where the scan's points can land over the window (not the whole reference)
    world = transform_points(prior, points)
    lo = np.minimum(world.min(axis=0), prior[:2]) - margin
    hi = np.maximum(world.max(axis=0), prior[:2]) + margin
    ox, oy = float(lo[0]), float(lo[1])
    w = int(math.ceil((hi[0] - lo[0]) / resolution)) + 1
    h = int(math.ceil((hi[1] - lo[1]) / resolution)) + 1
    grid = np.zeros((h, w), dtype=np.float32)
    inside = (reference[:, 0] > lo[0] - 1) & (reference[:, 0] < hi[0] + 1) & (reference[:, 1] > lo[1] - 1) & (reference[:, 1] < hi[1] + 1)
    k.splat(grid, np.ascontiguousarray(reference[inside]), ox, oy, resolution, smear_deviation)
    coarse = k.block_max(grid, block)
    x, y, th, best = k.search(grid, coarse, block, points, float(prior[0]), float(prior[1]), thetas, half_cells,
                              ox, oy, resolution, 0.0, 0.0, -1.0)
    if best < 0:
        return Match(prior, 0.0, np.diag([1e6, 1e6, 1e6]))
    x, y, th, response, jtj, sse = k.refine(grid, points, x, y, th, ox, oy, resolution, resolution, step, 10)
    runner_up = -1.0
    if ambiguity_radius > 0:
        runner_up = k.search(grid, coarse, block, points, float(prior[0]), float(prior[1]), thetas, half_cells,
                             ox, oy, resolution, x, y, ambiguity_radius)[3]
    return Match((float(x), float(y), float(wrap(th))), float(response), _covariance(jtj), float(best), float(runner_up))


def _covariance(jtj: NDArray[np.float64]) -> NDArray[np.float64]:
    """_RESPONSE_VARIANCE (J^T J)^-1 (1e6 on the diagonal when singular): a direction the scan does not pin
    (a corridor's axis) has little curvature, so a large variance."""
    try:
        cov = _RESPONSE_VARIANCE * np.linalg.inv(jtj)
    except np.linalg.LinAlgError:
        return np.diag([1e6, 1e6, 1e6])
    if not np.all(np.isfinite(cov)):
        return np.diag([1e6, 1e6, 1e6])
    return 0.5 * (cov + cov.T)
