"""Planar odometry: exact constant-twist integration and a wheel-odometry integrator."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ._checks import check_non_negative, check_positive, check_vector
from ._kinematics import Kinematics

__all__ = ["integrate_twist", "wrap_angle", "WheelOdometry", "tick_delta"]

_TICK_MODULUS = 1 << 32
_HALF_TICK_MODULUS = 1 << 31


def wrap_angle(angle: ArrayLike) -> NDArray[np.float64] | float:
    """Wrap an angle (rad) into [-pi, pi)."""
    wrapped = (np.asarray(angle, dtype=np.float64) + math.pi) % (2.0 * math.pi) - math.pi
    return float(wrapped) if wrapped.ndim == 0 else wrapped


def _arc_factors(phi: float, dt_sec: float) -> tuple[float, float]:
    """``(sin(phi)/phi * dt, (1 - cos(phi))/phi * dt)`` with a series near phi = 0."""
    if abs(phi) < 1e-6:
        phi2 = phi * phi
        return dt_sec * (1.0 - phi2 / 6.0), dt_sec * (phi / 2.0 - phi * phi2 / 24.0)
    return dt_sec * math.sin(phi) / phi, dt_sec * (1.0 - math.cos(phi)) / phi


def integrate_twist(pose: ArrayLike, body_twist: ArrayLike, dt_sec: float) -> NDArray[np.float64]:
    """Move a planar pose along a body twist held constant for ``dt_sec`` (exact arc).

    Parameters
    ----------
    pose : array_like, shape (3,)
        ``(x, y, theta)`` in the odometry frame (m, m, rad).
    body_twist : array_like, shape (3,)
        ``(vx, vy, omega)`` in the body frame (m/s, m/s, rad/s).
    dt_sec : float
        Duration of the step, >= 0.

    Returns
    -------
    ndarray, shape (3,)
        The new pose, heading wrapped into [-pi, pi).
    """
    x, y, theta = check_vector("pose", pose, 3)
    vx, vy, omega = check_vector("body_twist", body_twist, 3)
    dt = check_non_negative("dt_sec", dt_sec)
    a, b = _arc_factors(omega * dt, dt)
    # displacement in the starting body frame
    dx_body = a * vx - b * vy
    dy_body = b * vx + a * vy
    c, s = math.cos(theta), math.sin(theta)
    return np.array(
        [x + c * dx_body - s * dy_body, y + s * dx_body + c * dy_body, float(wrap_angle(theta + omega * dt))]
    )


def tick_delta(ticks: ArrayLike, previous_ticks: ArrayLike) -> NDArray[np.int64]:
    """Signed tick increments between two readings of wrapping 32-bit counters."""
    now = np.asarray(ticks, dtype=np.int64)
    before = np.asarray(previous_ticks, dtype=np.int64)
    return (now - before + _HALF_TICK_MODULUS) % _TICK_MODULUS - _HALF_TICK_MODULUS


class WheelOdometry:
    """Integrates wheel motion into a pose, a twist and a growing pose covariance.

    Feed it wheel speeds with a step length, absolute wheel angles with stamps,
    or encoder tick counters with stamps. Each step is integrated as an exact
    arc. The pose covariance grows with the distance travelled and the angle
    turned: per step a body-frame noise ``diag(k_lin*d, k_lin*d,
    k_ang*|dtheta| + k_head*d)`` is rotated into the odometry frame and added to
    the propagated covariance.

    Parameters
    ----------
    kinematics : DiffDrive or Mecanum
        The drive that maps wheel speeds to body twists.
    ticks_per_revolution : float, optional
        Encoder resolution, needed only for :meth:`update_from_ticks`.
    linear_variance_per_m : float
        ``k_lin``: position variance (m^2) added per metre travelled.
    angular_variance_per_rad : float
        ``k_ang``: heading variance (rad^2) added per radian turned.
    heading_variance_per_m : float
        ``k_head``: heading variance (rad^2) added per metre travelled.
    """

    def __init__(
        self,
        kinematics: Kinematics,
        *,
        ticks_per_revolution: float | None = None,
        linear_variance_per_m: float = 1e-3,
        angular_variance_per_rad: float = 1e-3,
        heading_variance_per_m: float = 1e-4,
    ) -> None:
        self.kinematics = kinematics
        self.ticks_per_revolution = (
            None if ticks_per_revolution is None else check_positive("ticks_per_revolution", ticks_per_revolution)
        )
        self.linear_variance_per_m = check_non_negative("linear_variance_per_m", linear_variance_per_m)
        self.angular_variance_per_rad = check_non_negative("angular_variance_per_rad", angular_variance_per_rad)
        self.heading_variance_per_m = check_non_negative("heading_variance_per_m", heading_variance_per_m)
        self.reset()

    def __repr__(self) -> str:
        x, y, th = self.pose
        return f"<WheelOdometry {self.kinematics!r} pose=({x:.3f}, {y:.3f}, {th:.3f}) distance={self.distance_m:.3f} m>"

    def reset(self, pose: ArrayLike = (0.0, 0.0, 0.0)) -> None:
        """Set the pose (default origin), zero the twist, covariance and distance, forget references."""
        self.pose = check_vector("pose", pose, 3).copy()
        self.twist = np.zeros(3)
        self.covariance = np.zeros((3, 3))
        self.distance_m = 0.0
        self._last_positions: NDArray[np.float64] | None = None
        self._last_ticks: NDArray[np.int64] | None = None
        self._last_stamp_sec: float | None = None

    def update_from_wheel_speeds(self, wheel_speeds: ArrayLike, dt_sec: float) -> NDArray[np.float64]:
        """Integrate wheel speeds (rad/s, shape ``(n_wheels,)``) held for ``dt_sec``; returns the pose."""
        wheels = check_vector("wheel_speeds", wheel_speeds, self.kinematics.n_wheels)
        dt = check_non_negative("dt_sec", dt_sec)
        self._step(self.kinematics.body_twist(wheels) * dt)
        self.twist = self.kinematics.body_twist(wheels)
        return self.pose

    def update_from_wheel_positions(self, positions_rad: ArrayLike, stamp_sec: float) -> NDArray[np.float64]:
        """Integrate absolute wheel angles (rad, shape ``(n_wheels,)``) read at ``stamp_sec``.

        The first call only sets the reference. The twist is the increment over the stamp difference.
        """
        positions = check_vector("positions_rad", positions_rad, self.kinematics.n_wheels)
        if self._last_positions is not None and self._last_stamp_sec is not None:
            self._apply_increment(positions - self._last_positions, float(stamp_sec) - self._last_stamp_sec)
        self._last_positions = positions.copy()
        self._last_stamp_sec = float(stamp_sec)
        return self.pose

    def update_from_ticks(self, ticks: ArrayLike, stamp_sec: float) -> NDArray[np.float64]:
        """Integrate wrapping 32-bit encoder counters (shape ``(n_wheels,)``) read at ``stamp_sec``."""
        if self.ticks_per_revolution is None:
            raise ValueError("update_from_ticks needs ticks_per_revolution; pass it to WheelOdometry(...)")
        counts = np.asarray(ticks, dtype=np.int64)
        if counts.shape != (self.kinematics.n_wheels,):
            raise ValueError(f"ticks must have shape ({self.kinematics.n_wheels},), got shape {counts.shape}")
        if self._last_ticks is not None and self._last_stamp_sec is not None:
            delta_rad = np.asarray(tick_delta(counts, self._last_ticks), dtype=np.float64) * (
                2.0 * math.pi / self.ticks_per_revolution
            )
            self._apply_increment(delta_rad, float(stamp_sec) - self._last_stamp_sec)
        self._last_ticks = counts.copy()
        self._last_stamp_sec = float(stamp_sec)
        return self.pose

    def _apply_increment(self, delta_rad: NDArray[np.float64], dt_sec: float) -> None:
        displacement = self.kinematics.body_twist(delta_rad)
        self._step(displacement)
        if dt_sec > 0.0:
            self.twist = displacement / dt_sec

    def _step(self, displacement: NDArray[np.float64]) -> None:
        """Integrate a body displacement ``(dx, dy, dtheta)`` (twist times time) as one arc."""
        before = self.pose
        after = integrate_twist(before, displacement, 1.0)
        dx_world, dy_world = after[0] - before[0], after[1] - before[1]
        distance = math.hypot(displacement[0], displacement[1])
        turned = abs(displacement[2])
        jacobian = np.array([[1.0, 0.0, -dy_world], [0.0, 1.0, dx_world], [0.0, 0.0, 1.0]])
        mid = before[2] + 0.5 * displacement[2]
        c, s = math.cos(mid), math.sin(mid)
        rotation = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
        noise = np.diag(
            [
                self.linear_variance_per_m * distance,
                self.linear_variance_per_m * distance,
                self.angular_variance_per_rad * turned + self.heading_variance_per_m * distance,
            ]
        )
        self.covariance = jacobian @ self.covariance @ jacobian.T + rotation @ noise @ rotation.T
        self.distance_m += distance
        self.pose = after
