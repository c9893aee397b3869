"""MPPI's parameters: nav2_mppi_controller's names and defaults (the optimizer's, the motion
models', the path handler's and goal checker's, and each critic's as ``<Critic>.<name>``).

Defaults are the upstream source's (``Optimizer::getParams``, each critic's ``initialize``), not
its README's example file. ``from_dict`` takes a flat mapping as a ROS parameter file holds it
under the controller (``batch_size``, ``GoalCritic.cost_weight``, ...); an unknown name is an
error that suggests the nearest valid one.
"""

from __future__ import annotations

import difflib
import math
from dataclasses import dataclass, field, fields
from typing import Any

__all__ = ["CRITICS", "MOTION_MODELS", "MppiParameters"]

#: the critics this controller implements, with their parameters' upstream defaults
CRITICS: dict[str, dict[str, Any]] = {
    "ConstraintCritic": {"enabled": True, "cost_power": 1, "cost_weight": 4.0},
    "ObstaclesCritic": {"enabled": True, "cost_power": 1, "repulsion_weight": 1.5, "critical_weight": 20.0,
                        "collision_cost": 100000.0, "collision_margin_distance": 0.10, "near_goal_distance": 0.5},
    "GoalCritic": {"enabled": True, "cost_power": 1, "cost_weight": 5.0, "threshold_to_consider": 1.4},
    "GoalAngleCritic": {"enabled": True, "cost_power": 1, "cost_weight": 3.0, "threshold_to_consider": 0.5},
    "PathAlignCritic": {"enabled": True, "cost_power": 1, "cost_weight": 10.0, "max_path_occupancy_ratio": 0.07,
                        "offset_from_furthest": 20, "trajectory_point_step": 4, "threshold_to_consider": 0.5,
                        "use_path_orientations": False},
    "PathFollowCritic": {"enabled": True, "cost_power": 1, "cost_weight": 5.0, "offset_from_furthest": 6,
                         "threshold_to_consider": 1.4},
    "PathAngleCritic": {"enabled": True, "cost_power": 1, "cost_weight": 2.2, "offset_from_furthest": 4,
                        "threshold_to_consider": 0.5, "max_angle_to_furthest": 0.785398},
    "PreferForwardCritic": {"enabled": True, "cost_power": 1, "cost_weight": 5.0, "threshold_to_consider": 0.5},
}

#: motion model names (Nav2's ``motion_model`` values) -> whether it moves sideways
MOTION_MODELS = {"DiffDrive": False, "Omni": True, "Ackermann": False}


def _near(name: str, names: Any) -> str:
    near = difflib.get_close_matches(name, list(names), n=1)
    return f"; did you mean {near[0]!r}?" if near else ""


@dataclass
class MppiParameters:
    """nav2_mppi_controller's parameters (see the module doc); ``critic_params`` holds each critic's.

    rclpy difference: names are flat on the navigation server (no ``FollowPath.`` plugin prefix), a
    positive ``ax_min``/``ay_min`` is refused rather than sign-flipped, and the noise is seeded.
    """

    batch_size: int = 1000
    time_steps: int = 56
    model_dt: float = 0.05
    iteration_count: int = 1
    temperature: float = 0.3
    gamma: float = 0.015
    vx_max: float = 0.5
    vx_min: float = -0.35
    vy_max: float = 0.5
    wz_max: float = 1.9
    ax_max: float = 3.0
    ax_min: float = -3.0
    ay_max: float = 3.0
    ay_min: float = -3.0
    az_max: float = 3.5
    vx_std: float = 0.2
    vy_std: float = 0.2
    wz_std: float = 0.4
    retry_attempt_limit: int = 1
    regenerate_noises: bool = False
    sgf_order: int = 2
    motion_model: str = "DiffDrive"
    #: AckermannConstraints.min_turning_r
    min_turning_r: float = 0.2
    #: the path handler's: how far along the plan the controller looks (m) ...
    prune_distance: float = 2.0
    #: ... and how far along it, from the last closest point, it searches for the robot (m; <= 0: the whole plan)
    max_robot_pose_search_dist: float = -1.0
    #: SimpleGoalChecker's
    xy_goal_tolerance: float = 0.25
    yaw_goal_tolerance: float = 0.25
    #: 1 / controller_frequency (s); equal to model_dt, the sequence shifts each cycle (Nav2's rule)
    controller_period: float = 0.05
    #: the noise generator's seed (Nav2 seeds from the clock; a seed makes runs repeatable)
    seed: int = 0
    critics: tuple[str, ...] = ("ConstraintCritic", "ObstaclesCritic", "GoalCritic", "GoalAngleCritic", "PathAlignCritic",
                                "PathFollowCritic", "PathAngleCritic", "PreferForwardCritic")
    critic_params: dict[str, dict[str, Any]] = field(default_factory=lambda: {k: dict(v) for k, v in CRITICS.items()})

    def __post_init__(self) -> None:
        self.critics = tuple(self.critics)
        for name in self.critics:
            if name not in CRITICS:
                raise ValueError(f"MPPI parameter critics: unknown critic {name!r}{_near(name, CRITICS)} "
                                 f"(implemented: {', '.join(CRITICS)})")
        if self.motion_model not in MOTION_MODELS:
            raise ValueError(f"MPPI parameter motion_model: expected one of {', '.join(MOTION_MODELS)}, "
                             f"found {self.motion_model!r}{_near(self.motion_model, MOTION_MODELS)}")
        for name in ("batch_size", "time_steps", "iteration_count"):
            if int(getattr(self, name)) < 1:
                raise ValueError(f"MPPI parameter {name}: expected an integer >= 1, found {getattr(self, name)!r}")
        if self.time_steps < 2:
            raise ValueError(f"MPPI parameter time_steps: expected >= 2, found {self.time_steps}")
        for name in ("model_dt", "temperature", "controller_period"):
            if not float(getattr(self, name)) > 0.0:
                raise ValueError(f"MPPI parameter {name}: expected a number > 0, found {getattr(self, name)!r}")
        if self.controller_period > self.model_dt + 1e-6:
            raise ValueError(f"MPPI: controller period {self.controller_period:g} s (1 / controller_frequency) is longer "
                             f"than model_dt {self.model_dt:g} s; set model_dt to the controller period (as Nav2 requires)")
        if self.sgf_order not in (1, 2):
            raise ValueError(f"MPPI parameter sgf_order: expected 1 or 2, found {self.sgf_order!r}")
        # Nav2 flips the sign of a positive deceleration limit (with a warning); here the value must be right
        for name in ("ax_min", "ay_min"):
            if getattr(self, name) > 0.0:
                raise ValueError(f"MPPI parameter {name}: expected a value <= 0 (a deceleration), found {getattr(self, name)}")

    @property
    def holonomic(self) -> bool:
        return MOTION_MODELS[self.motion_model]

    @property
    def shift_control_sequence(self) -> bool:
        return math.isclose(self.controller_period, self.model_dt, abs_tol=1e-6)

    def critic(self, name: str) -> dict[str, Any]:
        return self.critic_params[name]

    @classmethod
    def from_dict(cls, values: dict[str, Any]) -> MppiParameters:
        """Parameters from a flat dict (``vx_max``, ``critics``, ``GoalCritic.cost_weight``, ...)."""
        names = {f.name for f in fields(cls)} - {"critic_params"}
        top: dict[str, Any] = {}
        critic_params = {k: dict(v) for k, v in CRITICS.items()}
        for key, value in values.items():
            critic, dot, name = key.partition(".")
            if dot:
                if critic not in CRITICS:
                    raise ValueError(f"unknown MPPI critic {critic!r} in parameter {key!r}{_near(critic, CRITICS)}")
                if name not in CRITICS[critic]:
                    raise ValueError(f"unknown {critic} parameter {name!r}{_near(name, CRITICS[critic])}")
                default = CRITICS[critic][name]
                critic_params[critic][name] = type(default)(value)
            elif key in names:
                top[key] = value
            else:
                raise ValueError(f"unknown MPPI parameter {key!r}{_near(key, names | set(CRITICS))}")
        return cls(**top, critic_params=critic_params)

    @staticmethod
    def flat_defaults() -> dict[str, Any]:
        """Every parameter with its default, flat (critics' as ``<Critic>.<name>``), as a node declares them."""
        out: dict[str, Any] = {f.name: f.default for f in fields(MppiParameters)
                               if f.name not in ("critic_params", "controller_period")}
        out["critics"] = list(out["critics"])
        for critic, params in CRITICS.items():
            out.update({f"{critic}.{name}": value for name, value in params.items()})
        return out
