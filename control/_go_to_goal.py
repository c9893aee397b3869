"""The seeds' go-to-goal controller for a base that drives forward and turns."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from ._checks import check_positive, check_vector
from ._odometry import wrap_angle

__all__ = ["GoToGoal", "DriveCommand"]


@dataclass(frozen=True, slots=True)
class DriveCommand:
    """A unicycle command: ``linear`` (m/s) forward and ``angular`` (rad/s) counter-clockwise.

    ``done`` is True once the goal is reached; the speeds are then zero.
    """

    linear: float
    angular: float
    done: bool


class GoToGoal:
    """Drive to a point: turn on the spot first if it lies far off the heading.

    - distance to the goal within ``goal_tolerance_m``: stop (``done``); if a final
      yaw was given, first turn on the spot to it within ``yaw_tolerance_rad``;
    - heading error beyond ``heading_threshold_rad``: rotate in place with
      ``angular = k_angular * error`` (clamped to ``max_angular``);
    - otherwise drive with ``linear = k_linear * distance`` (clamped to
      ``max_linear``, scaled down by ``cos(heading error)``) while correcting the
      heading proportionally.

    Parameters
    ----------
    k_linear, k_angular : float
        Proportional gains (1/s), > 0.
    max_linear, max_angular : float
        Speed limits (m/s, rad/s), > 0.
    heading_threshold_rad : float
        Heading error (rad) beyond which the base turns in place, > 0.
    goal_tolerance_m : float
        Distance (m) at which the position goal counts as reached, > 0.
    yaw_tolerance_rad : float
        Final-yaw tolerance (rad) when a goal yaw is given, > 0.
    """

    def __init__(
        self,
        *,
        k_linear: float = 1.0,
        k_angular: float = 2.0,
        max_linear: float = 0.5,
        max_angular: float = 1.5,
        heading_threshold_rad: float = 0.5,
        goal_tolerance_m: float = 0.05,
        yaw_tolerance_rad: float = 0.05,
    ) -> None:
        self.k_linear = check_positive("k_linear", k_linear)
        self.k_angular = check_positive("k_angular", k_angular)
        self.max_linear = check_positive("max_linear", max_linear)
        self.max_angular = check_positive("max_angular", max_angular)
        self.heading_threshold_rad = check_positive("heading_threshold_rad", heading_threshold_rad)
        self.goal_tolerance_m = check_positive("goal_tolerance_m", goal_tolerance_m)
        self.yaw_tolerance_rad = check_positive("yaw_tolerance_rad", yaw_tolerance_rad)

    def __repr__(self) -> str:
        return (
            f"GoToGoal(k_linear={self.k_linear}, k_angular={self.k_angular}, max_linear={self.max_linear}, "
            f"max_angular={self.max_angular}, heading_threshold_rad={self.heading_threshold_rad}, "
            f"goal_tolerance_m={self.goal_tolerance_m})"
        )

    def _turn(self, error: float) -> float:
        return float(np.clip(self.k_angular * error, -self.max_angular, self.max_angular))

    def compute(self, pose: ArrayLike, goal: ArrayLike) -> DriveCommand:
        """Command for the base at ``pose`` ``(x, y, theta)`` toward ``goal`` ``(x, y)`` or ``(x, y, yaw)``."""
        x, y, theta = check_vector("pose", pose, 3)
        target = np.asarray(goal, dtype=np.float64)
        if target.shape not in ((2,), (3,)):
            raise ValueError(f"goal must have shape (2,) as (x, y) or (3,) as (x, y, yaw), got shape {target.shape}")
        dx, dy = target[0] - x, target[1] - y
        distance = math.hypot(dx, dy)
        if distance <= self.goal_tolerance_m:
            if target.shape == (3,):
                yaw_error = float(wrap_angle(target[2] - theta))
                if abs(yaw_error) > self.yaw_tolerance_rad:
                    return DriveCommand(0.0, self._turn(yaw_error), False)
            return DriveCommand(0.0, 0.0, True)
        heading_error = float(wrap_angle(math.atan2(dy, dx) - theta))
        if abs(heading_error) > self.heading_threshold_rad:
            return DriveCommand(0.0, self._turn(heading_error), False)
        linear = min(self.k_linear * distance, self.max_linear) * math.cos(heading_error)
        return DriveCommand(linear, self._turn(heading_error), False)
