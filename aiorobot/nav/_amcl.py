"""AMCL-style localisation on a known map: Nav2 amcl's motion and likelihood-field models, as a pure class.

Parameters keep nav2_amcl's names: ``min_particles``/``max_particles`` (KLD-adaptive count
with ``pf_err``, ``pf_z``), ``alpha1``..``alpha5`` (motion noise; ``robot_model_type``
``differential`` or ``omnidirectional`` for mecanum bases), ``z_hit``, ``z_rand``, ``sigma_hit``,
``laser_likelihood_max_dist``, ``laser_min_range``/``laser_max_range``, ``max_beams``,
``update_min_d``, ``update_min_a``, ``resample_interval``, ``recovery_alpha_slow``/``_fast``.

The filter is deterministic for a given ``seed``. The sensor model's kernel is Numba (GIL released).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

__all__ = ["Amcl", "AmclParameters", "likelihood_field"]


@dataclass
class AmclParameters:
    """nav2_amcl parameters (names and Jazzy defaults)."""

    min_particles: int = 500
    max_particles: int = 2000
    pf_err: float = 0.05
    pf_z: float = 0.99
    alpha1: float = 0.2
    alpha2: float = 0.2
    alpha3: float = 0.2
    alpha4: float = 0.2
    alpha5: float = 0.2
    robot_model_type: str = "differential"
    z_hit: float = 0.5
    z_rand: float = 0.5
    sigma_hit: float = 0.2
    laser_likelihood_max_dist: float = 2.0
    laser_min_range: float = -1.0
    laser_max_range: float = 100.0
    max_beams: int = 60
    update_min_d: float = 0.25
    update_min_a: float = 0.2
    resample_interval: int = 1
    recovery_alpha_slow: float = 0.0
    recovery_alpha_fast: float = 0.0

    def __post_init__(self) -> None:
        if self.robot_model_type not in ("differential", "omnidirectional", "nav2_amcl::DifferentialMotionModel", "nav2_amcl::OmniMotionModel"):
            raise ValueError(f"robot_model_type: expected 'differential' or 'omnidirectional', found {self.robot_model_type!r}")
        if not 0 < self.min_particles <= self.max_particles:
            raise ValueError(f"particles: need 0 < min_particles <= max_particles, found {self.min_particles}, {self.max_particles}")


def likelihood_field(occupied: NDArray[np.bool_], resolution: float, max_dist: float) -> NDArray[np.float64]:
    """Distance (m) from every cell to the nearest occupied cell, clipped at ``max_dist`` (AMCL's map)."""
    import cv2

    if not occupied.any():
        return np.full(occupied.shape, max_dist)
    d = cv2.distanceTransform((~occupied).astype(np.uint8), cv2.DIST_L2, cv2.DIST_MASK_PRECISE).astype(np.float64) * resolution
    return np.minimum(d, max_dist)


def _wrap(a: NDArray[np.float64] | float) -> NDArray[np.float64] | float:
    return (np.asarray(a) + np.pi) % (2 * np.pi) - np.pi


class Amcl:
    """A particle filter on an occupancy map.

    ``occupied`` (H, W) bool, row 0 at ``origin[1]`` (OccupancyGrid layout). Call
    :meth:`set_initial_pose` (or :meth:`global_localization`), then :meth:`update` with each
    odometry pose and scan; read :attr:`pose` and :attr:`covariance`.
    """

    def __init__(self, occupied: NDArray[np.bool_], resolution: float, origin: tuple[float, float],
                 params: AmclParameters | None = None, *, seed: int = 0) -> None:
        self.p = params or AmclParameters()
        self.occupied = np.asarray(occupied, dtype=bool)
        self.resolution = float(resolution)
        self.origin = (float(origin[0]), float(origin[1]))
        self.field = likelihood_field(self.occupied, self.resolution, self.p.laser_likelihood_max_dist)
        self.rng = np.random.default_rng(seed)
        self.particles = np.zeros((self.p.max_particles, 3))
        self.weights = np.full(self.p.max_particles, 1.0 / self.p.max_particles)
        self._last_odom: NDArray[np.float64] | None = None
        self._updates = 0
        self._w_slow = self._w_fast = 0.0
        self.initialized = False

    # -- initialisation -----------------------------------------------------------------

    def set_initial_pose(self, x: float, y: float, yaw: float, cov_xx: float = 0.25, cov_yy: float = 0.25, cov_aa: float = 0.0685) -> None:
        """Particles around (x, y, yaw) with Nav2's default initial covariance (0.5 m, 0.26 rad std)."""
        n = self.p.max_particles
        self.particles = np.column_stack([
            self.rng.normal(x, math.sqrt(cov_xx), n),
            self.rng.normal(y, math.sqrt(cov_yy), n),
            _wrap(self.rng.normal(yaw, math.sqrt(cov_aa), n)),
        ])
        self.weights = np.full(n, 1.0 / n)
        self._last_odom = None
        self.initialized = True

    def global_localization(self) -> None:
        """Particles spread uniformly over the free cells (nav2_amcl's ~/reinitialize_global_localization)."""
        free = np.argwhere(~self.occupied)
        n = self.p.max_particles
        pick = free[self.rng.integers(len(free), size=n)]
        self.particles = np.column_stack([
            self.origin[0] + (pick[:, 1] + self.rng.random(n)) * self.resolution,
            self.origin[1] + (pick[:, 0] + self.rng.random(n)) * self.resolution,
            self.rng.uniform(-np.pi, np.pi, n),
        ])
        self.weights = np.full(n, 1.0 / n)
        self._last_odom = None
        self.initialized = True

    # -- filter -------------------------------------------------------------------------

    def update(self, odom: tuple[float, float, float], ranges: NDArray[np.float64], angle_min: float, angle_increment: float,
               *, range_min: float = 0.0, range_max: float = 12.0, laser_pose: tuple[float, float, float] = (0.0, 0.0, 0.0),
               force: bool = False) -> bool:
        """Move the particles by the odometry change since the last update and weigh them with the scan.

        Returns True when the filter updated (moved more than ``update_min_d`` / ``update_min_a``,
        or ``force``); the first call only records the odometry.
        """
        if not self.initialized:
            raise RuntimeError("amcl: no initial pose; call set_initial_pose() or global_localization() first")
        o = np.asarray(odom, dtype=np.float64)
        if self._last_odom is None:
            self._last_odom = o
            return False
        d = o - self._last_odom
        moved = math.hypot(d[0], d[1])
        turned = abs(float(_wrap(d[2])))
        if not force and moved < self.p.update_min_d and turned < self.p.update_min_a:
            return False
        self._motion(self._last_odom, o)
        self._last_odom = o
        self._sense(np.asarray(ranges, dtype=np.float64), angle_min, angle_increment, range_min, range_max, laser_pose)
        self._updates += 1
        if self._updates % max(1, self.p.resample_interval) == 0:
            self._resample()
        return True

    def _motion(self, old: NDArray[np.float64], new: NDArray[np.float64]) -> None:
        """Sample the odometry motion model (nav2_amcl DifferentialMotionModel / OmniMotionModel)."""
        p, rng, parts = self.p, self.rng, self.particles
        n = len(parts)
        dx, dy = new[0] - old[0], new[1] - old[1]
        trans = math.hypot(dx, dy)
        if p.robot_model_type.endswith(("omnidirectional", "OmniMotionModel")):
            delta_bearing = float(_wrap(math.atan2(dy, dx) - old[2])) if trans > 1e-9 else 0.0
            rot = float(_wrap(new[2] - old[2]))
            trans_sd = math.sqrt(p.alpha3 * trans * trans + p.alpha1 * rot * rot)
            rot_sd = math.sqrt(p.alpha4 * rot * rot + p.alpha2 * trans * trans)
            strafe_sd = math.sqrt(p.alpha1 * rot * rot + p.alpha5 * trans * trans)
            bearing = delta_bearing + parts[:, 2]
            t_hat = trans + rng.normal(0, trans_sd, n)
            s_hat = rng.normal(0, strafe_sd, n)
            parts[:, 0] += t_hat * np.cos(bearing) + s_hat * np.cos(bearing + np.pi / 2)
            parts[:, 1] += t_hat * np.sin(bearing) + s_hat * np.sin(bearing + np.pi / 2)
            parts[:, 2] = _wrap(parts[:, 2] + rot + rng.normal(0, rot_sd, n))
            return
        rot1 = float(_wrap(math.atan2(dy, dx) - old[2])) if trans >= 0.01 else 0.0
        rot2 = float(_wrap(new[2] - old[2] - rot1))
        # Nav2: noise uses the smaller of the forward and backward rotation
        r1n = min(abs(rot1), abs(float(_wrap(rot1 - math.pi))))
        r2n = min(abs(rot2), abs(float(_wrap(rot2 - math.pi))))
        r1 = rot1 - rng.normal(0, math.sqrt(p.alpha1 * r1n * r1n + p.alpha2 * trans * trans), n)
        tr = trans - rng.normal(0, math.sqrt(p.alpha3 * trans * trans + p.alpha4 * (r1n * r1n + r2n * r2n)), n)
        r2 = rot2 - rng.normal(0, math.sqrt(p.alpha1 * r2n * r2n + p.alpha2 * trans * trans), n)
        parts[:, 0] += tr * np.cos(parts[:, 2] + r1)
        parts[:, 1] += tr * np.sin(parts[:, 2] + r1)
        parts[:, 2] = _wrap(parts[:, 2] + r1 + r2)

    def _sense(self, ranges: NDArray[np.float64], angle_min: float, inc: float, range_min: float, range_max: float,
               laser_pose: tuple[float, float, float]) -> None:
        from ._kernels import likelihood_weights

        p = self.p
        count = len(ranges)
        step = max(1, count // max(1, p.max_beams))
        idx = np.arange(0, count, step)[: p.max_beams]
        angles = angle_min + idx * inc
        rmin = max(range_min, p.laser_min_range)
        rmax = min(range_max, p.laser_max_range) if p.laser_max_range > 0 else range_max
        factor = likelihood_weights(self.particles, np.ascontiguousarray(ranges[idx]), np.ascontiguousarray(angles), self.field,
                                    self.origin[0], self.origin[1], self.resolution, laser_pose[0], laser_pose[1], laser_pose[2],
                                    rmin, rmax, p.z_hit, p.z_rand, p.sigma_hit, p.laser_likelihood_max_dist)
        w = self.weights * factor
        total = w.sum()
        if not total > 0 or not math.isfinite(total):
            self.weights = np.full(len(w), 1.0 / len(w))
            return
        avg = total / len(w)
        if p.recovery_alpha_slow > 0:
            self._w_slow += p.recovery_alpha_slow * (avg - self._w_slow)
            self._w_fast += p.recovery_alpha_fast * (avg - self._w_fast)
        self.weights = w / total

    def _kld_count(self) -> int:
        """KLD-sampling's particle count for the current spread (Fox 2003, as nav2_amcl's pf_resample_limit)."""
        p = self.p
        bins = {(int(x // 0.5), int(y // 0.5), int(a // (10 * math.pi / 180))) for x, y, a in self.particles}
        k = len(bins)
        if k <= 1:
            return p.min_particles
        from statistics import NormalDist

        z = NormalDist().inv_cdf(p.pf_z)
        a = 1.0 - 2.0 / (9.0 * (k - 1))
        b = math.sqrt(2.0 / (9.0 * (k - 1)))
        n = int(math.ceil((k - 1) / (2.0 * p.pf_err) * (a + b * z) ** 3))
        return min(max(n, p.min_particles), p.max_particles)

    def _resample(self) -> None:
        """Low-variance resampling to the KLD count; random particles added when recovery says the fit is poor."""
        n = self._kld_count()
        w = self.weights
        positions = (self.rng.random() + np.arange(n)) / n
        idx = np.minimum(np.searchsorted(np.cumsum(w), positions), len(w) - 1)
        new = self.particles[idx].copy()
        if self.p.recovery_alpha_slow > 0 and self._w_slow > 0:
            prob = max(0.0, 1.0 - self._w_fast / self._w_slow)
            rand = self.rng.random(n) < prob
            if rand.any():
                free = np.argwhere(~self.occupied)
                pick = free[self.rng.integers(len(free), size=int(rand.sum()))]
                new[rand, 0] = self.origin[0] + (pick[:, 1] + 0.5) * self.resolution
                new[rand, 1] = self.origin[1] + (pick[:, 0] + 0.5) * self.resolution
                new[rand, 2] = self.rng.uniform(-np.pi, np.pi, int(rand.sum()))
        self.particles = new
        self.weights = np.full(n, 1.0 / n)

    # -- estimate -------------------------------------------------------------------------

    @property
    def pose(self) -> tuple[float, float, float]:
        """The weighted mean pose (x, y, yaw), the yaw as a circular mean."""
        w = self.weights
        x = float(np.dot(w, self.particles[:, 0]))
        y = float(np.dot(w, self.particles[:, 1]))
        yaw = math.atan2(float(np.dot(w, np.sin(self.particles[:, 2]))), float(np.dot(w, np.cos(self.particles[:, 2]))))
        return x, y, yaw

    @property
    def covariance(self) -> NDArray[np.float64]:
        """3x3 covariance of (x, y, yaw) about the mean (yaw differences wrapped)."""
        mx, my, myaw = self.pose
        d = np.column_stack([self.particles[:, 0] - mx, self.particles[:, 1] - my, _wrap(self.particles[:, 2] - myaw)])
        return (d * self.weights[:, None]).T @ d

    def __len__(self) -> int:
        return len(self.particles)
