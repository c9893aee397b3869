"""Regulated Pure Pursuit: Nav2's ``nav2_regulated_pure_pursuit_controller`` as a pure class.

Same parameters and regulation functions (``regulation_functions.hpp``):

- lookahead: ``lookahead_dist``, or with ``use_velocity_scaled_lookahead_dist`` the current speed
  times ``lookahead_time`` clamped to [``min_lookahead_dist``, ``max_lookahead_dist``]; the carrot is
  interpolated on the path where it first leaves the lookahead circle;
- curvature regulation: below ``regulated_linear_scaling_min_radius`` the speed scales down with
  the turning radius; cost regulation: near obstacles (cost -> distance by inverting the inflation
  function with ``inflation_cost_scaling_factor``) the speed scales with distance/``cost_scaling_dist``;
  both floored at ``regulated_linear_scaling_min_speed``; approach: within
  ``approach_velocity_scaling_dist`` of the goal the speed scales with the remaining distance, not
  below ``min_approach_linear_velocity``;
- rotate to heading: when the carrot is more than ``rotate_to_heading_min_angle`` off the heading
  (and at the goal, to the goal's yaw) the base turns in place at ``rotate_to_heading_angular_vel``;
- collision detection: the commanded arc is projected forward for up to
  ``max_allowed_time_to_collision_up_to_carrot``; the costmap's footprint touching an obstacle at a
  pose on it (:meth:`Costmap.in_collision`) stops the base and sets ``collision_ahead``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from ._costmap import FREE_SPACE, INSCRIBED_INFLATED_OBSTACLE, NO_INFORMATION, Costmap

__all__ = ["RegulatedPurePursuit", "RppCommand", "RppParameters"]


@dataclass
class RppParameters:
    """Nav2 RPP parameters (names and defaults of nav2_regulated_pure_pursuit_controller, Jazzy)."""

    desired_linear_vel: float = 0.5
    lookahead_dist: float = 0.6
    min_lookahead_dist: float = 0.3
    max_lookahead_dist: float = 0.9
    lookahead_time: float = 1.5
    use_velocity_scaled_lookahead_dist: bool = False
    min_approach_linear_velocity: float = 0.05
    approach_velocity_scaling_dist: float = 0.6
    use_regulated_linear_velocity_scaling: bool = True
    regulated_linear_scaling_min_radius: float = 0.9
    regulated_linear_scaling_min_speed: float = 0.25
    use_cost_regulated_linear_velocity_scaling: bool = True
    cost_scaling_dist: float = 0.3
    cost_scaling_gain: float = 1.0
    inflation_cost_scaling_factor: float = 3.0
    use_rotate_to_heading: bool = True
    rotate_to_heading_angular_vel: float = 1.8
    rotate_to_heading_min_angle: float = 0.785
    max_angular_accel: float = 3.2
    use_collision_detection: bool = True
    max_allowed_time_to_collision_up_to_carrot: float = 1.0
    xy_goal_tolerance: float = 0.25
    yaw_goal_tolerance: float = 0.25
    control_period: float = 0.05
    extra: dict[str, float] = field(default_factory=dict)

    @classmethod
    def from_dict(cls, values: dict[str, object]) -> RppParameters:
        """Parameters from a dict; an unknown name raises ValueError suggesting the nearest valid one."""
        import difflib
        from dataclasses import fields

        names = [f.name for f in fields(cls) if f.name != "extra"]
        for key in values:
            if key not in names:
                near = difflib.get_close_matches(key, names, n=1)
                raise ValueError(f"unknown Regulated Pure Pursuit parameter {key!r}" + (f"; did you mean {near[0]!r}?" if near else ""))
        return cls(**values)  # type: ignore[arg-type]


@dataclass(frozen=True)
class RppCommand:
    """One control step's output: body-frame velocities and why."""

    linear: float
    angular: float
    lookahead: float
    carrot: tuple[float, float]
    goal_reached: bool = False
    collision_ahead: bool = False
    rotating: bool = False


def _wrap(a: float) -> float:
    return (a + math.pi) % (2 * math.pi) - math.pi


class RegulatedPurePursuit:
    """Follow a path (N, 3) of (x, y, yaw) in the costmap's frame; call :meth:`step` each control period."""

    def __init__(self, params: RppParameters | None = None, costmap: Costmap | None = None) -> None:
        self.p = params or RppParameters()
        self.costmap = costmap
        self.path: NDArray[np.float64] = np.zeros((0, 3))
        self._last_angular = 0.0
        self._progress = 0
        #: the speed the regulation starts from: ``desired_linear_vel`` unless a speed limit holds
        self.desired_linear_vel = self.p.desired_linear_vel

    def set_speed_limit(self, speed_limit: float, percentage: bool) -> None:
        """Nav2's ``setSpeedLimit``: cap the speed at ``speed_limit`` (percent of ``desired_linear_vel``
        or m/s); 0.0 (NO_SPEED_LIMIT) lifts the cap.

        rclpy difference: an absolute limit above ``desired_linear_vel`` does not raise the speed.
        """
        from ._filters import limited_speed

        self.desired_linear_vel = min(limited_speed(self.p.desired_linear_vel, speed_limit, percentage), self.p.desired_linear_vel)

    def set_plan(self, poses: NDArray[np.float64]) -> None:
        poses = np.asarray(poses, dtype=np.float64)
        if poses.ndim != 2 or poses.shape[1] != 3 or len(poses) < 1 or not np.isfinite(poses).all():
            raise ValueError(f"set_plan: expected finite (N, 3) poses (x, y, yaw) with N >= 1, got shape {poses.shape}")
        self.path = poses
        self._progress = 0

    # -- the step ------------------------------------------------------------------------

    def step(self, pose: tuple[float, float, float], speed: float = 0.0) -> RppCommand:
        """The command for the robot at ``pose`` (x, y, yaw) moving at ``speed`` (m/s)."""
        if len(self.path) == 0:
            raise ValueError("step: no plan; call set_plan first")
        p = self.p
        x, y, yaw = pose
        goal = self.path[-1]
        dist_to_goal = math.hypot(goal[0] - x, goal[1] - y)
        if dist_to_goal <= p.xy_goal_tolerance:
            err = _wrap(goal[2] - yaw)
            if abs(err) <= p.yaw_goal_tolerance or not p.use_rotate_to_heading:
                self._last_angular = 0.0
                return RppCommand(0.0, 0.0, 0.0, (float(goal[0]), float(goal[1])), goal_reached=True)
            return self._rotate(err, (float(goal[0]), float(goal[1])))
        lookahead = self._lookahead(speed)
        carrot = self._carrot(x, y, lookahead)
        # carrot in the robot frame
        dx, dy = carrot[0] - x, carrot[1] - y
        cx = math.cos(yaw) * dx + math.sin(yaw) * dy
        cy = -math.sin(yaw) * dx + math.cos(yaw) * dy
        angle_to_carrot = math.atan2(cy, cx)
        if p.use_rotate_to_heading and abs(angle_to_carrot) > p.rotate_to_heading_min_angle:
            return self._rotate(angle_to_carrot, carrot, lookahead)
        d2 = cx * cx + cy * cy
        curvature = 2.0 * cy / d2 if d2 > 1e-9 else 0.0
        linear = self._regulate(curvature, (x, y), self._remaining(x, y))
        angular = linear * curvature
        collision = False
        if p.use_collision_detection and self.costmap is not None and self._collides(pose, linear, angular, math.sqrt(d2)):
            linear = angular = 0.0
            collision = True
        self._last_angular = angular
        return RppCommand(linear, angular, lookahead, carrot, collision_ahead=collision)

    # -- pieces ---------------------------------------------------------------------------

    def _lookahead(self, speed: float) -> float:
        p = self.p
        if not p.use_velocity_scaled_lookahead_dist:
            return p.lookahead_dist
        return min(max(abs(speed) * p.lookahead_time, p.min_lookahead_dist), p.max_lookahead_dist)

    def _carrot(self, x: float, y: float, lookahead: float) -> tuple[float, float]:
        """The point where the path (from the closest point on) leaves the lookahead circle."""
        path = self.path[:, :2]
        # progress only moves forward: search the closest point from the last one on
        window = path[self._progress :]
        d = np.hypot(window[:, 0] - x, window[:, 1] - y)
        self._progress += int(np.argmin(d))
        for i in range(self._progress, len(path) - 1):
            a, b = path[i], path[i + 1]
            if math.hypot(b[0] - x, b[1] - y) >= lookahead:
                # interpolate on segment a-b where the distance from (x, y) equals lookahead
                fx, fy = a[0] - x, a[1] - y
                ex, ey = b[0] - a[0], b[1] - a[1]
                qa = ex * ex + ey * ey
                qb = 2 * (fx * ex + fy * ey)
                qc = fx * fx + fy * fy - lookahead * lookahead
                disc = qb * qb - 4 * qa * qc
                if qa > 1e-12 and disc >= 0:
                    t = (-qb + math.sqrt(disc)) / (2 * qa)
                    t = min(max(t, 0.0), 1.0)
                    return (float(a[0] + t * ex), float(a[1] + t * ey))
                return (float(b[0]), float(b[1]))
        return (float(path[-1, 0]), float(path[-1, 1]))

    def remaining(self, x: float, y: float) -> float:
        """Path length (m) from the robot's nearest path point to the goal, plus the gap to it."""
        return self._remaining(x, y)

    def _remaining(self, x: float, y: float) -> float:
        path = self.path[self._progress :, :2]
        if len(path) == 0:
            return 0.0
        first = math.hypot(path[0, 0] - x, path[0, 1] - y)
        return first + float(np.linalg.norm(np.diff(path, axis=0), axis=1).sum()) if len(path) > 1 else first

    def _regulate(self, curvature: float, xy: tuple[float, float], remaining: float) -> float:
        p = self.p
        raw = self.desired_linear_vel
        curv_vel = raw
        if p.use_regulated_linear_velocity_scaling and abs(curvature) > 1e-9:
            radius = abs(1.0 / curvature)
            if radius < p.regulated_linear_scaling_min_radius:
                curv_vel = raw * (1.0 - abs(radius - p.regulated_linear_scaling_min_radius) / p.regulated_linear_scaling_min_radius)
        cost_vel = raw
        if p.use_cost_regulated_linear_velocity_scaling and self.costmap is not None:
            cost = self.costmap.cost_at(*xy)
            if cost not in (NO_INFORMATION, FREE_SPACE) and cost < INSCRIBED_INFLATED_OBSTACLE:
                min_dist = (-1.0 / p.inflation_cost_scaling_factor) * math.log(cost / (INSCRIBED_INFLATED_OBSTACLE - 1.0)) + self.costmap.robot_radius
                if min_dist < p.cost_scaling_dist:
                    cost_vel = raw * p.cost_scaling_gain * min_dist / p.cost_scaling_dist
        linear = min(curv_vel, cost_vel)
        linear = max(linear, p.regulated_linear_scaling_min_speed)
        if remaining < p.approach_velocity_scaling_dist:
            scaled = raw * remaining / p.approach_velocity_scaling_dist
            linear = min(linear, max(scaled, p.min_approach_linear_velocity))
        return min(linear, raw)

    def _rotate(self, angle: float, carrot: tuple[float, float], lookahead: float = 0.0) -> RppCommand:
        p = self.p
        target = math.copysign(p.rotate_to_heading_angular_vel, angle)
        dv = p.max_angular_accel * p.control_period
        angular = min(max(target, self._last_angular - dv), self._last_angular + dv)
        # do not overshoot: slow down as the error closes (v^2 = 2 a theta)
        cap = math.sqrt(2.0 * p.max_angular_accel * abs(angle))
        angular = math.copysign(min(abs(angular), cap), angular)
        self._last_angular = angular
        return RppCommand(0.0, angular, lookahead, carrot, rotating=True)

    def _collides(self, pose: tuple[float, float, float], linear: float, angular: float, carrot_dist: float) -> bool:
        assert self.costmap is not None
        if abs(linear) < 1e-6:
            return False
        horizon = min(self.p.max_allowed_time_to_collision_up_to_carrot, carrot_dist / abs(linear))
        dt = self.costmap.resolution / abs(linear)
        x, y, th = pose
        t = 0.0
        while t < horizon:
            t += dt
            x += linear * math.cos(th) * dt
            y += linear * math.sin(th) * dt
            th += angular * dt
            if self.costmap.in_collision(x, y, th):  # the costmap's footprint at each pose of the arc
                return True
        return False
