"""MPPI: Nav2's ``nav2_mppi_controller`` (Model Predictive Path Integral) as a pure class.

Each control cycle (``Optimizer::evalControl``), for the robot at ``pose`` moving at ``speed``:

1. the plan is pruned as Nav2's path handler does: from the path point nearest the robot
   (searched forward from the last one) up to ``prune_distance`` along it; its length is the
   critics' ``local_path_length``;
2. ``batch_size`` control sequences of ``time_steps`` steps are sampled around the current optimal
   one (Gaussian noise of ``vx_std``/``vy_std``/``wz_std``, drawn once unless ``regenerate_noises``),
   their velocities limited by the accelerations (``ax_max``, ``ax_min``, ``ay_*``, ``az_max``) and
   rolled out every ``model_dt`` with the motion model (``DiffDrive``, ``Omni``, ``Ackermann``);
3. the critics score each trajectory (see :data:`~aiorobot.nav.MPPI_CRITICS`);
4. the new optimal sequence is the softmax(-cost / ``temperature``) weighted mean of the samples
   (with the ``gamma`` control cost), smoothed by a Savitzky-Golay filter (``sgf_order``) and
   clamped to the velocity and acceleration limits; with ``model_dt`` equal to the control period
   its second step is the command and the sequence shifts by one.

When every sampled trajectory collides (Nav2's ``fail_flag``) the optimizer resets and retries
``retry_attempt_limit`` times; then the step returns a stop with ``collision_ahead`` (Nav2 throws
NoValidControl, which the controller server turns into a failed FollowPath and a recovery).

Goal: SimpleGoalChecker's rule (``xy_goal_tolerance``, then ``yaw_goal_tolerance``, stateful).
The rollouts and critics are Numba kernels (:mod:`._mppi_kernels`).

Differences from Nav2: the obstacles critic is ObstaclesCritic with a circular robot (no
CostCritic, no footprint check); PathAngleCritic has its forward-preference mode only; no
TwirlingCritic, VelocityDeadbandCritic, trajectory validator, model delays or speed-limit zones.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from . import _mppi_kernels as k
from ._costmap import INSCRIBED_INFLATED_OBSTACLE, NO_INFORMATION, Costmap
from ._geometry import wrap_angle as _wrap
from ._mppi_parameters import MppiParameters

__all__ = ["Mppi", "MppiCommand"]

_MODEL_CODE = {"DiffDrive": k.DIFF_DRIVE, "Omni": k.OMNI, "Ackermann": k.ACKERMANN}
#: Savitzky-Golay 9-point coefficients by order (utils::savitskyGolayFilter)
_SGF = {1: np.full(9, 1.0 / 9.0), 2: np.array([-21.0, 14.0, 39.0, 54.0, 59.0, 54.0, 39.0, 14.0, -21.0]) / 231.0}


@dataclass(frozen=True)
class MppiCommand:
    """One control cycle's output: body-frame velocities (m/s, m/s, rad/s) and why."""

    linear: float
    angular: float
    lateral: float = 0.0
    goal_reached: bool = False
    #: every sampled trajectory collides: the base stops (Nav2's NoValidControl)
    collision_ahead: bool = False
    #: the controller turns in place (no forward or sideways speed): progress checks let it be
    rotating: bool = False


class Mppi:
    """Follow a path (N, 3) of (x, y, yaw) in the costmap's frame; call :meth:`step` each control period."""

    def __init__(self, params: MppiParameters | None = None, costmap: Costmap | None = None) -> None:
        self.p = params or MppiParameters()
        self._base = self.p  # the limits set_speed_limit scales
        self.costmap = costmap
        self.path: NDArray[np.float64] = np.zeros((0, 3))
        p = self.p
        b, t = int(p.batch_size), int(p.time_steps)
        self._rng = np.random.default_rng(p.seed)
        self._std = np.array([p.vx_std, p.vy_std if p.holonomic else 0.0, p.wz_std], dtype=np.float64)
        self._noise = np.zeros((3, b, t))
        self._cv = np.zeros((3, b, t))
        self._v = np.zeros((3, b, t))
        self._xs, self._ys, self._yaws = np.zeros((b, t)), np.zeros((b, t)), np.zeros((b, t))
        self._costs = np.zeros(b)
        self._travelled = np.zeros(b)
        self._accel = np.array([p.ax_max, p.ax_min, p.ay_max, p.ay_min, p.az_max], dtype=np.float64)
        self._progress = 0
        self._xy_reached = False
        #: ObstaclesCritic's distance by cost, for the costmap's (robot_radius, cost_scaling_factor, inflation_radius)
        self._distances: tuple[tuple[float, float, float] | None, NDArray[np.float64]] = (None, np.zeros(256))
        self.reset()

    # -- state -----------------------------------------------------------------------------

    def reset(self) -> None:
        """Optimizer::reset: a zero control sequence and history, fresh noise, no last command."""
        t = int(self.p.time_steps)
        self.control_sequence = np.zeros((3, t))
        self._history = np.zeros((4, 3))
        self.last_command = np.zeros(3)
        self._draw_noise()

    def _draw_noise(self) -> None:
        self._rng.standard_normal(out=self._noise)
        self._noise *= self._std[:, None, None]

    def set_speed_limit(self, speed_limit: float, percentage: bool) -> None:
        """Nav2's ``setSpeedLimit`` (Optimizer::setSpeedLimit): scale ``vx_max``, ``vx_min``, ``vy_max``
        and ``wz_max`` by ``speed_limit`` percent, or by ``speed_limit / vx_max`` for an absolute
        limit in m/s; 0.0 (NO_SPEED_LIMIT) restores them.

        rclpy difference (as RPP's): an absolute limit above ``vx_max`` does not raise the speeds.
        """
        import dataclasses

        base = self._base
        if speed_limit == 0.0:
            ratio = 1.0
        elif percentage:
            ratio = min(speed_limit / 100.0, 1.0)
        else:
            ratio = min(speed_limit / base.vx_max, 1.0) if base.vx_max > 0 else 1.0
        if ratio == 1.0:
            self.p = base
        else:
            self.p = dataclasses.replace(base, vx_max=base.vx_max * ratio, vx_min=base.vx_min * ratio,
                                         vy_max=base.vy_max * ratio, wz_max=base.wz_max * ratio)

    def set_plan(self, poses: NDArray[np.float64]) -> None:
        poses = np.asarray(poses, dtype=np.float64)
        if poses.ndim != 2 or poses.shape[1] != 3 or len(poses) < 1 or not np.isfinite(poses).all():
            raise ValueError(f"set_plan: expected finite (N, 3) poses (x, y, yaw) with N >= 1, got shape {poses.shape}")
        self.path = np.ascontiguousarray(poses)
        self._progress = 0

    @property
    def trajectories(self) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
        """The last cycle's sampled trajectories: x, y, yaw, each (batch_size, time_steps)."""
        return self._xs, self._ys, self._yaws

    def optimal_trajectory(self, pose: tuple[float, float, float]) -> NDArray[np.float64]:
        """The current optimal control sequence rolled out from ``pose``: (time_steps, 3) x, y, yaw."""
        dt = self.p.model_dt
        x, y, th = pose
        out = np.empty((self.control_sequence.shape[1], 3))
        for i, (vx, vy, wz) in enumerate(self.control_sequence.T):
            x += (vx * math.cos(th) - vy * math.sin(th)) * dt
            y += (vx * math.sin(th) + vy * math.cos(th)) * dt
            th += wz * dt
            out[i] = x, y, th
        return out

    # -- the cycle -------------------------------------------------------------------------

    def step(self, pose: tuple[float, float, float], speed: float | tuple[float, float, float] | None = None) -> MppiCommand:
        """The command for the robot at ``pose`` (x, y, yaw) moving at ``speed``.

        ``speed`` is the measured (vx, vy, wz) or just vx (the rest taken from the last command);
        None uses the last command (Nav2's ``open_loop``). As Nav2 does in closed loop, the state
        speed is the last command clamped to what the accelerations allow from the measured one.
        """
        if len(self.path) == 0:
            raise ValueError("step: no plan; call set_plan first")
        p = self.p
        x, y, yaw = pose
        goal = self.path[-1]
        if self._goal_reached(x, y, yaw, goal):
            self.reset()
            return MppiCommand(0.0, 0.0, goal_reached=True)
        state_speed = self._state_speed(speed)
        local = self._prune(x, y)
        pose_arr = np.array([x, y, yaw], dtype=np.float64)
        for attempt in range(int(p.retry_attempt_limit) + 1):
            failed = False
            for _ in range(int(p.iteration_count)):
                failed = self._optimize(pose_arr, state_speed, local)
            if not failed:
                break
            self.reset()  # Optimizer::fallback
        else:
            self.reset()
            return MppiCommand(0.0, 0.0, collision_ahead=True)
        offset = 1 if p.shift_control_sequence else 0
        vx, vy, wz = (float(v) for v in self.control_sequence[:, offset])
        if not p.holonomic:
            vy = 0.0
        self.last_command = np.array([vx, vy, wz])
        if p.shift_control_sequence:
            self.control_sequence[:, :-1] = self.control_sequence[:, 1:]
        return MppiCommand(vx, wz, vy, rotating=abs(vx) < 1e-3 and abs(vy) < 1e-3 and abs(wz) > 1e-3)

    def remaining(self, x: float, y: float) -> float:
        """Path length (m) from the robot's nearest path point to the goal, plus the gap to it."""
        path = self.path[self._progress :, :2]
        if len(path) == 0:
            return 0.0
        first = math.hypot(path[0, 0] - x, path[0, 1] - y)
        return first + float(np.linalg.norm(np.diff(path, axis=0), axis=1).sum())

    def _goal_reached(self, x: float, y: float, yaw: float, goal: NDArray[np.float64]) -> bool:
        """SimpleGoalChecker (stateful): once within xy tolerance, only the heading must come within its own."""
        if not self._xy_reached and math.hypot(goal[0] - x, goal[1] - y) > self.p.xy_goal_tolerance:
            return False
        self._xy_reached = True
        return abs(_wrap(goal[2] - yaw)) <= self.p.yaw_goal_tolerance

    def _state_speed(self, speed: float | tuple[float, float, float] | None) -> NDArray[np.float64]:
        last = self.last_command
        if speed is None:
            return last.copy()
        measured = np.array([float(speed), last[1], last[2]]) if np.isscalar(speed) else np.asarray(speed, dtype=np.float64)
        p = self.p
        dt = p.controller_period
        out = np.array([min(max(last[0], measured[0] + dt * p.ax_min), measured[0] + dt * p.ax_max), 0.0,
                        min(max(last[2], measured[2] - dt * p.az_max), measured[2] + dt * p.az_max)])
        if p.holonomic:
            out[1] = min(max(last[1], measured[1] + dt * p.ay_min), measured[1] + dt * p.ay_max)
        return out

    def _prune(self, x: float, y: float) -> NDArray[np.float64]:
        """The path handler: from the nearest point (searched forward) up to ``prune_distance`` along the plan."""
        p = self.p
        rest = self.path[self._progress :]
        seg = np.hypot(*np.diff(rest[:, :2], axis=0).T)
        along = np.concatenate(([0.0], np.cumsum(seg)))
        if p.max_robot_pose_search_dist > 0:
            upper = int(np.searchsorted(along, p.max_robot_pose_search_dist, side="right"))
            upper = max(upper, 1)
        else:
            upper = len(rest)
        closest = int(np.argmin(np.hypot(rest[:upper, 0] - x, rest[:upper, 1] - y)))
        self._progress += closest
        along = along[closest:] - along[closest]
        end = int(np.searchsorted(along, p.prune_distance, side="right")) + 1  # first_after_integrated_distance
        return self.path[self._progress : self._progress + end]

    def _optimize(self, pose: NDArray[np.float64], speed: NDArray[np.float64], local: NDArray[np.float64]) -> bool:
        """One iteration (generate, score, update); True when every trajectory collides."""
        p = self.p
        cs = self.control_sequence
        # applyControlSequenceInterIterationConstraints
        if p.shift_control_sequence:
            cs[:, 0] = speed
        else:
            d = p.controller_period
            cs[0, 0] = k.clamp_by_accel(speed[0], cs[0, 0], d * p.ax_min, d * p.ax_max)
            cs[2, 0] = k.clamp_by_accel(speed[2], cs[2, 0], -d * p.az_max, d * p.az_max)
            if p.holonomic:
                cs[1, 0] = k.clamp_by_accel(speed[1], cs[1, 0], d * p.ay_min, d * p.ay_max)
        if p.regenerate_noises:
            self._draw_noise()
        k.rollout(self._noise, cs, speed, pose, p.model_dt, self._accel, p.holonomic, self._cv, self._v,
                  self._xs, self._ys, self._yaws, self._travelled)
        self._costs[:] = 0.0
        failed = self._score(pose, local)
        k.update_control_sequence(self._costs, self._cv, cs, p.gamma, self._std, p.temperature, p.holonomic)
        self._smooth()
        self._constrain(speed)
        return failed

    # -- critics ---------------------------------------------------------------------------

    def _score(self, pose: NDArray[np.float64], local: NDArray[np.float64]) -> bool:
        """CriticManager::evalTrajectoriesScores over ``critics`` in order; True: Nav2's fail_flag."""
        p = self.p
        costs, xs, ys, yaws, v = self._costs, self._xs, self._ys, self._yaws, self._v
        seg = np.hypot(*np.diff(local[:, :2], axis=0).T)
        path_dist = np.concatenate(([0.0], np.cumsum(seg)))
        length = float(path_dist[-1])
        goal = local[-1]
        furthest: int | None = None
        valid: NDArray[np.bool_] | None = None
        failed = False
        for name in p.critics:
            c = p.critic(name)
            if not c["enabled"]:
                continue
            w, pw = float(c.get("cost_weight", 0.0)), int(c["cost_power"])
            if name == "ConstraintCritic":
                k.constraint_critic(v, p.model_dt, p.vx_max, p.vx_min, p.vy_max if p.holonomic else 0.0,
                                    _MODEL_CODE[p.motion_model], p.min_turning_r, w, pw, costs)
            elif name == "GoalCritic":
                if length <= c["threshold_to_consider"]:
                    k.goal_critic(xs, ys, float(goal[0]), float(goal[1]), w, pw, costs)
            elif name == "GoalAngleCritic":
                if length <= c["threshold_to_consider"]:
                    k.goal_angle_critic(yaws, float(goal[2]), w, pw, costs)
            elif name == "PreferForwardCritic":
                if length >= c["threshold_to_consider"]:
                    k.prefer_forward_critic(v, p.model_dt, w, pw, costs)
            elif name == "ObstaclesCritic":
                failed = self._obstacles(c, length) or failed
            elif name in ("PathAlignCritic", "PathFollowCritic", "PathAngleCritic"):
                if length < c["threshold_to_consider"] or (name == "PathFollowCritic" and len(local) < 2):
                    continue
                if furthest is None:
                    furthest = int(k.furthest_reached_path_point(xs, ys, self._travelled, local, path_dist))
                if valid is None:
                    valid = self._path_valid(local)
                if name == "PathAlignCritic":
                    self._path_align(c, local, path_dist, furthest, valid)
                elif name == "PathFollowCritic":
                    size = len(local) - 1
                    idx = min(furthest + int(c["offset_from_furthest"]), size)
                    while idx < size - 1 and not valid[idx]:
                        idx += 1
                    k.path_follow_critic(xs, ys, float(local[idx, 0]), float(local[idx, 1]), w, pw, costs)
                else:
                    idx = min(furthest + int(c["offset_from_furthest"]), len(local) - 1)
                    tx, ty = float(local[idx, 0]), float(local[idx, 1])
                    if abs(_wrap(math.atan2(ty - pose[1], tx - pose[0]) - pose[2])) >= c["max_angle_to_furthest"]:
                        k.path_angle_critic(xs, ys, yaws, tx, ty, w, pw, costs)
        return failed

    def _path_valid(self, local: NDArray[np.float64]) -> NDArray[np.bool_]:
        """utils::findPathCosts: a path point is invalid in a lethal or inscribed cell (unknown is tracked: valid)."""
        n = len(local) - 1
        if self.costmap is None or n <= 0:
            return np.ones(max(n, 1), dtype=np.bool_)
        cm = self.costmap
        cols = np.floor((local[:n, 0] - cm.origin[0]) / cm.resolution).astype(np.int64)
        rows = np.floor((local[:n, 1] - cm.origin[1]) / cm.resolution).astype(np.int64)
        inside = (rows >= 0) & (cols >= 0) & (rows < cm.shape[0]) & (cols < cm.shape[1])
        cost = np.full(n, NO_INFORMATION, dtype=np.int64)
        cost[inside] = cm.cost[rows[inside], cols[inside]]
        return inside & ((cost < INSCRIBED_INFLATED_OBSTACLE) | (cost == NO_INFORMATION))

    def _path_align(self, c: dict, local: NDArray[np.float64], path_dist: NDArray[np.float64], furthest: int,
                    valid: NDArray[np.bool_]) -> None:
        segments = furthest
        if segments < int(c["offset_from_furthest"]) or segments < 1:
            return
        invalid = int(np.count_nonzero(~valid[:segments]))  # Nav2 counts over the whole reached run
        if invalid > 2 and invalid / segments > c["max_path_occupancy_ratio"]:
            return
        k.path_align_critic(self._xs, self._ys, self._yaws, local, path_dist, valid, segments,
                            int(c["trajectory_point_step"]), bool(c["use_path_orientations"]),
                            float(c["cost_weight"]), int(c["cost_power"]), self._costs)

    def _obstacles(self, c: dict, length: float) -> bool:
        cm = self.costmap
        if cm is None:
            return False
        key = (cm.robot_radius, cm.cost_scaling_factor, cm.inflation_radius)
        if self._distances[0] != key:
            self._distances = (key, k.obstacle_distances(*key))
        return bool(k.obstacles_critic(self._xs, self._ys, cm.cost, float(cm.origin[0]), float(cm.origin[1]),
                                       float(cm.resolution), True, self._distances[1],
                                       float(cm.inflation_radius), float(c["collision_margin_distance"]),
                                       length < c["near_goal_distance"], float(c["critical_weight"]),
                                       float(c["repulsion_weight"]), float(c["collision_cost"]), int(c["cost_power"]),
                                       self._costs))

    # -- the sequence ----------------------------------------------------------------------

    def _smooth(self) -> None:
        """utils::savitskyGolayFilter over each axis (needs >= 21 steps), then the history update."""
        cs = self.control_sequence
        n = cs.shape[1] - 1
        if n >= 20:
            coeffs = _SGF[self.p.sgf_order]
            for a in range(3):
                padded = np.concatenate((self._history[:, a], cs[a], np.full(4, cs[a, -1])))
                cs[a, :n] = np.correlate(padded, coeffs, mode="valid")[:n]
        offset = 1 if self.p.shift_control_sequence else 0
        self._history[:-1] = self._history[1:]
        self._history[-1] = cs[:, offset]

    def _constrain(self, speed: NDArray[np.float64]) -> None:
        """Optimizer::applyControlSequenceConstraints: speed limits, then accelerations step to step."""
        p = self.p
        cs = self.control_sequence
        if p.motion_model == "Ackermann":
            self._ackermann(cs)
        if not p.holonomic:
            cs[1] = 0.0
        if p.shift_control_sequence:
            cs[:, 0] = speed
        k.constrain_sequence(cs, speed, np.array([p.vx_min, -p.vy_max, -p.wz_max]), np.array([p.vx_max, p.vy_max, p.wz_max]),
                             self._accel, p.controller_period, p.model_dt, p.holonomic)
        if p.motion_model == "Ackermann":
            self._ackermann(cs)

    def _ackermann(self, cs: NDArray[np.float64]) -> None:
        limit = np.abs(cs[0]) / self.p.min_turning_r
        np.clip(cs[2], -limit, limit, out=cs[2])


