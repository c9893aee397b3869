"""The simulated base: kinematics with slip, acceleration limits, collisions, and drifting odometry.

Ground truth moves by ``(1 - wheel_slip)`` times what the wheels turned; odometry
believes ``(1 + odom_scale_error)`` times it, with multiplicative noise. Either
error alone makes odometry drift from ground truth the way a real base does.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from aiorobot.control import DiffDrive, Kinematics, Mecanum

from ._world import World

__all__ = ["RobotBody", "make_kinematics"]

#: A robot touching a wall stays "in contact" (one collision) until it is this far from it.
_CONTACT_MARGIN_M = 0.02


def integrate_twist(pose: NDArray[np.float64], twist: NDArray[np.float64], dt_sec: float) -> NDArray[np.float64]:
    """``aiorobot.control.integrate_twist`` (exact arc) on plain floats: the simulator calls it every step."""
    x, y, theta = float(pose[0]), float(pose[1]), float(pose[2])
    vx, vy, omega = float(twist[0]), float(twist[1]), float(twist[2])
    phi = omega * dt_sec
    if abs(phi) < 1e-6:
        phi2 = phi * phi
        a, b = dt_sec * (1.0 - phi2 / 6.0), dt_sec * (phi / 2.0 - phi * phi2 / 24.0)
    else:
        a, b = dt_sec * math.sin(phi) / phi, dt_sec * (1.0 - math.cos(phi)) / phi
    dx, dy = a * vx - b * vy, b * vx + a * vy
    c, s = math.cos(theta), math.sin(theta)
    yaw = (theta + phi + math.pi) % (2.0 * math.pi) - math.pi
    return np.array([x + c * dx - s * dy, y + s * dx + c * dy, yaw])


def make_kinematics(robot: str, *, wheel_radius: float = 0.05, wheel_separation: float = 0.3,
                    half_length: float = 0.15, half_width: float = 0.15) -> Kinematics:
    """``DiffDrive`` for ``"diff"``, ``Mecanum`` for ``"mecanum"`` (the control package's conventions)."""
    if robot == "diff":
        return DiffDrive(wheel_radius, wheel_separation)
    if robot == "mecanum":
        return Mecanum(wheel_radius, half_length, half_width)
    raise ValueError(f"robot: expected 'diff' or 'mecanum', found {robot!r}")


class RobotBody:
    """A planar base driven by body-twist commands on a :class:`World`.

    Parameters
    ----------
    kinematics : DiffDrive or Mecanum
        Maps body twists to wheel speeds (``vy`` is dropped for a diff drive).
    pose : array_like, shape (3,)
        Start ``(x, y, yaw)`` in the map frame.
    radius : float
        Footprint radius (m) for collisions.
    footprint : array_like, shape (M, 2), optional
        A polygon footprint in the base frame (a mecanum base is a rectangle); replaces the disc
        of ``radius`` for collisions.
    max_acceleration : array_like, shape (3,)
        Per-axis acceleration limits (m/s^2, m/s^2, rad/s^2).
    wheel_slip, odom_scale_error, odom_noise_std : float
        See the module docstring; ``odom_noise_std`` is the relative standard deviation per step.
    rng : numpy.random.Generator
        Noise source for odometry.
    """

    def __init__(
        self,
        kinematics: Kinematics,
        pose: ArrayLike = (0.0, 0.0, 0.0),
        *,
        radius: float = 0.2,
        footprint: ArrayLike | None = None,
        max_acceleration: ArrayLike = (2.0, 2.0, 4.0),
        wheel_slip: float = 0.0,
        odom_scale_error: float = 0.0,
        odom_noise_std: float = 0.0,
        rng: np.random.Generator | None = None,
    ) -> None:
        self.kinematics = kinematics
        self.holonomic = isinstance(kinematics, Mecanum)
        self.pose = np.asarray(pose, dtype=np.float64).copy()
        self.radius = float(radius)
        self.footprint = None if footprint is None else np.asarray(footprint, dtype=np.float64).reshape(-1, 2)
        if self.footprint is not None and (len(self.footprint) < 3 or not np.isfinite(self.footprint).all()):
            raise ValueError(f"footprint: expected 3 or more finite [x, y] points, found {self.footprint.tolist()}")
        #: the disc around the base that holds the footprint (a free disc is a free footprint)
        self._outer = self.radius if self.footprint is None else float(np.hypot(*self.footprint.T).max())
        self.max_acceleration = np.asarray(max_acceleration, dtype=np.float64)
        if not 0.0 <= wheel_slip < 1.0:
            raise ValueError(f"wheel_slip: expected a fraction in [0, 1), found {wheel_slip!r}")
        self.wheel_slip = float(wheel_slip)
        self.odom_scale_error = float(odom_scale_error)
        self.odom_noise_std = float(odom_noise_std)
        self.rng = rng if rng is not None else np.random.default_rng(0)
        self.command = np.zeros(3)
        self.velocity = np.zeros(3)  #: what the wheels turn, as a body twist
        self.twist = np.zeros(3)  #: ground-truth body twist
        self.acceleration = np.zeros(2)  #: ground-truth body-frame linear acceleration (m/s^2)
        self.odom_pose = np.zeros(3)
        self.odom_twist = np.zeros(3)
        self.wheel_positions = np.zeros(kinematics.n_wheels)
        self.wheel_velocities = np.zeros(kinematics.n_wheels)
        self.collisions = 0
        self.in_contact = False
        self.distance_m = 0.0

    def __repr__(self) -> str:
        x, y, yaw = self.pose
        return f"<RobotBody {self.kinematics!r} pose=({x:.3f}, {y:.3f}, {yaw:.3f}) collisions={self.collisions}>"

    def set_command(self, twist: ArrayLike) -> None:
        """Set the commanded body twist ``(vx, vy, omega)``; non-finite values raise ``ValueError``."""
        command = np.asarray(twist, dtype=np.float64).reshape(3).copy()
        if not np.all(np.isfinite(command)):
            raise ValueError(f"twist: expected finite values, found {command.tolist()}")
        if not self.holonomic:
            command[1] = 0.0
        self.command = command

    def set_wheel_speeds(self, wheel_speeds: ArrayLike) -> None:
        """Command the wheels directly (rad/s): the body follows their forward kinematics."""
        self.set_command(self.kinematics.body_twist(np.asarray(wheel_speeds, dtype=np.float64)))

    def step(self, dt_sec: float, world: World) -> None:
        """Advance ``dt_sec``: ramp the velocity toward the command, move, stop at walls, integrate odometry."""
        if dt_sec <= 0.0:
            return
        before = self.twist
        if not (self.velocity.any() or self.command.any()):  # parked: nothing moves, nothing drifts
            self.twist = np.zeros(3)
            self.acceleration = np.zeros(2)
            self.wheel_velocities = np.zeros(self.kinematics.n_wheels)
            self.odom_twist = np.zeros(3)
            return
        limit = self.max_acceleration * dt_sec
        self.velocity = self.velocity + np.clip(self.command - self.velocity, -limit, limit)
        twist = self.velocity * (1.0 - self.wheel_slip)
        candidate = integrate_twist(self.pose, twist, dt_sec)
        if self._free(world, candidate):
            self._move_to(candidate)
            if self.in_contact and self._free(world, candidate, _CONTACT_MARGIN_M):
                self.in_contact = False
        else:
            # move as far as the wall allows (bisection on the step), then stop
            lo, hi = 0.0, 1.0
            for _ in range(12):
                mid = 0.5 * (lo + hi)
                trial = integrate_twist(self.pose, twist, dt_sec * mid)
                if self._free(world, trial):
                    lo = mid
                else:
                    hi = mid
            if lo > 0.0:
                self._move_to(integrate_twist(self.pose, twist, dt_sec * lo))
            if not self.in_contact:
                self.collisions += 1
            self.in_contact = True
            self.velocity = np.zeros(3)
            twist = np.zeros(3)
        self.twist = twist
        dv = (twist[:2] - before[:2]) / dt_sec
        omega = twist[2]
        # body-frame acceleration of a rotating frame: dv/dt + omega x v
        self.acceleration = np.array([dv[0] - omega * twist[1], dv[1] + omega * twist[0]])
        self.wheel_velocities = self.kinematics.wheel_speeds(self.velocity)
        self.wheel_positions = self.wheel_positions + self.wheel_velocities * dt_sec
        believed = self.velocity * (1.0 + self.odom_scale_error)
        if self.odom_noise_std > 0.0 and np.any(believed != 0.0):
            believed = believed * (1.0 + self.rng.normal(0.0, self.odom_noise_std, 3))
        if not self.holonomic:
            believed[1] = 0.0
        self.odom_twist = believed
        self.odom_pose = integrate_twist(self.odom_pose, believed, dt_sec)

    def _free(self, world: World, pose: NDArray[np.float64], margin: float = 0.0) -> bool:
        """Whether the footprint (grown by ``margin`` m) at ``pose`` touches nothing."""
        x, y = float(pose[0]), float(pose[1])
        if self.footprint is None:
            return world.is_free_disc(x, y, self.radius + margin)
        if world.is_free_disc(x, y, self._outer + margin):
            return True
        v = self.footprint + np.sign(self.footprint) * margin
        c, s = math.cos(pose[2]), math.sin(pose[2])
        return world.is_free_polygon(np.column_stack([x + c * v[:, 0] - s * v[:, 1], y + s * v[:, 0] + c * v[:, 1]]))

    def _move_to(self, pose: NDArray[np.float64]) -> None:
        self.distance_m += math.hypot(pose[0] - self.pose[0], pose[1] - self.pose[1])
        self.pose = pose

    def odom_error(self, start: ArrayLike) -> NDArray[np.float64]:
        """Odometry pose minus the ground-truth pose expressed relative to ``start`` (``x, y, yaw``)."""
        sx, sy, syaw = np.asarray(start, dtype=np.float64)
        c, s = math.cos(-syaw), math.sin(-syaw)
        dx, dy = self.pose[0] - sx, self.pose[1] - sy
        truth = np.array([c * dx - s * dy, s * dx + c * dy, self.pose[2] - syaw])
        error = self.odom_pose - truth
        error[2] = (error[2] + math.pi) % (2.0 * math.pi) - math.pi
        return error
