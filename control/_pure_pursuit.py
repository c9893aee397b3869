"""Pure-pursuit path following for a forward-driving base."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ._checks import check_positive, check_vector
from ._go_to_goal import DriveCommand

__all__ = ["PurePursuit", "check_path"]


def check_path(path: ArrayLike) -> NDArray[np.float64]:
    """Coerce a path to float64 ``(N, 2)`` points; ``(N, 3)`` is accepted and its third column dropped."""
    points = np.asarray(path, dtype=np.float64)
    if points.ndim != 2 or points.shape[1] not in (2, 3) or points.shape[0] < 1:
        raise ValueError(
            f"path must have shape (N, 2) as (x, y) or (N, 3) with N >= 1, got shape {points.shape}"
        )
    if not np.all(np.isfinite(points[:, :2])):
        raise ValueError("path must hold finite coordinates, got NaN or inf")
    return np.ascontiguousarray(points[:, :2])


class PurePursuit:
    """Follow a polyline by steering toward a point ``lookahead_m`` ahead on it.

    The curvature to the lookahead point ``(x_l, y_l)`` in the body frame is
    ``2 * y_l / L**2`` with ``L`` its distance; ``angular = linear * curvature``.
    When the angular limit bites, the linear speed is reduced so the base keeps
    the same curvature. Progress along the path only moves forward, so a path
    that crosses itself is followed in order. Near the end the speed falls off
    linearly with the remaining distance; within ``goal_tolerance_m`` of the last
    point the command is zero and ``done``. A lookahead point behind the base
    makes it turn on the spot toward it.

    Parameters
    ----------
    path : array_like, shape (N, 2) or (N, 3)
        Waypoints in the odometry frame (x, y); a third column (z or yaw) is ignored.
    lookahead_m : float
        Lookahead distance, > 0.
    linear_speed : float
        Cruise speed (m/s), > 0.
    max_angular : float
        Yaw-rate limit (rad/s), > 0.
    goal_tolerance_m : float
        Distance to the last point at which the path is done, > 0.
    """

    def __init__(
        self,
        path: ArrayLike,
        *,
        lookahead_m: float = 0.3,
        linear_speed: float = 0.3,
        max_angular: float = 1.5,
        goal_tolerance_m: float = 0.05,
    ) -> None:
        self.lookahead_m = check_positive("lookahead_m", lookahead_m)
        self.linear_speed = check_positive("linear_speed", linear_speed)
        self.max_angular = check_positive("max_angular", max_angular)
        self.goal_tolerance_m = check_positive("goal_tolerance_m", goal_tolerance_m)
        self.set_path(path)

    def __repr__(self) -> str:
        return (
            f"<PurePursuit points={len(self.path)} lookahead_m={self.lookahead_m} "
            f"progress={self.progress_m:.3f}/{self.length_m:.3f} m>"
        )

    def set_path(self, path: ArrayLike) -> None:
        """Replace the path and restart from its beginning."""
        self.path = check_path(path)
        segments = np.diff(self.path, axis=0)
        self._segment_lengths = np.hypot(segments[:, 0], segments[:, 1])
        self._cumulative = np.concatenate([[0.0], np.cumsum(self._segment_lengths)])
        self.length_m = float(self._cumulative[-1])
        self.progress_m = 0.0

    def _point_at(self, s: float) -> NDArray[np.float64]:
        """The point at arc length ``s`` along the path (clamped to its ends)."""
        if len(self.path) == 1 or s <= 0.0:
            return self.path[0]
        if s >= self.length_m:
            return self.path[-1]
        i = int(np.searchsorted(self._cumulative, s, side="right")) - 1
        i = min(i, len(self._segment_lengths) - 1)
        t = (s - self._cumulative[i]) / self._segment_lengths[i] if self._segment_lengths[i] > 0 else 0.0
        return self.path[i] + t * (self.path[i + 1] - self.path[i])

    def _project(self, position: NDArray[np.float64]) -> float:
        """Arc length of the closest path point within ``[progress, progress + 2*lookahead]``.

        Searching only ahead of the current progress keeps the follower from jumping
        back to an earlier part of a path that passes near itself.
        """
        if len(self.path) == 1:
            return 0.0
        s_lo, s_hi = self.progress_m, self.progress_m + 2.0 * self.lookahead_m
        start, seg = self.path[:-1], np.diff(self.path, axis=0)
        lengths = np.maximum(self._segment_lengths, 1e-12)
        in_window = (self._cumulative[1:] >= s_lo) & (self._cumulative[:-1] <= s_hi)
        t_lo = np.clip((s_lo - self._cumulative[:-1]) / lengths, 0.0, 1.0)
        t_hi = np.clip((s_hi - self._cumulative[:-1]) / lengths, 0.0, 1.0)
        t = np.einsum("ij,ij->i", position - start, seg) / (lengths**2)
        t = np.clip(t, t_lo, t_hi)
        closest = start + t[:, None] * seg
        distance = np.where(in_window, np.hypot(*(closest - position).T), np.inf)
        if not np.any(np.isfinite(distance)):
            return self.progress_m
        best = int(np.argmin(distance))
        return max(self.progress_m, float(self._cumulative[best] + t[best] * self._segment_lengths[best]))

    def compute(self, pose: ArrayLike) -> DriveCommand:
        """Command for the base at ``pose`` ``(x, y, theta)``."""
        x, y, theta = check_vector("pose", pose, 3)
        position = np.array([x, y])
        self.progress_m = self._project(position)
        remaining_goal = math.hypot(*(self.path[-1] - position))
        if remaining_goal <= self.goal_tolerance_m and self.length_m - self.progress_m <= self.lookahead_m:
            return DriveCommand(0.0, 0.0, True)
        target = self._point_at(self.progress_m + self.lookahead_m)
        dx, dy = target - position
        c, s = math.cos(theta), math.sin(theta)
        x_l, y_l = c * dx + s * dy, -s * dx + c * dy
        distance2 = max(x_l * x_l + y_l * y_l, 1e-12)
        if x_l <= 0.0:
            # the target is behind: turn on the spot toward it
            angular = math.copysign(self.max_angular, y_l if y_l != 0.0 else 1.0)
            return DriveCommand(0.0, angular, False)
        curvature = 2.0 * y_l / distance2
        remaining_path = max(self.length_m - self.progress_m, remaining_goal)
        linear = self.linear_speed * min(1.0, remaining_path / self.lookahead_m)
        linear = max(linear, 0.1 * self.linear_speed)
        angular = linear * curvature
        if abs(angular) > self.max_angular:
            linear *= self.max_angular / abs(angular)
            angular = math.copysign(self.max_angular, angular)
        return DriveCommand(linear, angular, False)
