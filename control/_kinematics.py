"""Wheel kinematics of a differential drive and an X-configured mecanum base (REP 103).

Body twist: ``vx`` forward (m/s), ``vy`` left (m/s), ``omega`` counter-clockwise (rad/s).
Wheel speeds are in rad/s, positive when the wheel drives the robot forward.
"""

from __future__ import annotations

from typing import Any, Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ._checks import check_non_negative, check_positive

__all__ = ["DiffDrive", "Mecanum", "Kinematics", "saturate_wheel_speeds"]


def _out(array: NDArray[np.float64]) -> Any:
    """A 0-d result becomes a Python float so scalar calls return scalars."""
    return float(array) if array.ndim == 0 else array


class Kinematics(Protocol):
    """What the base controller and odometry need from a drive."""

    @property
    def wheel_radius(self) -> float: ...

    @property
    def n_wheels(self) -> int: ...

    @property
    def wheel_names(self) -> tuple[str, ...]: ...

    def wheel_speeds(self, body_twist: ArrayLike) -> NDArray[np.float64]: ...

    def body_twist(self, wheel_speeds: ArrayLike) -> NDArray[np.float64]: ...


class DiffDrive:
    """Differential drive: two wheels on one axle, ``wheel_separation`` apart.

    Parameters
    ----------
    wheel_radius : float
        Wheel radius in metres, > 0.
    wheel_separation : float
        Distance between the wheel contact points in metres, > 0.
    """

    n_wheels = 2
    wheel_names = ("left_wheel_joint", "right_wheel_joint")

    def __init__(self, wheel_radius: float, wheel_separation: float) -> None:
        self.wheel_radius = check_positive("wheel_radius", wheel_radius)
        self.wheel_separation = check_positive("wheel_separation", wheel_separation)

    def __repr__(self) -> str:
        return f"DiffDrive(wheel_radius={self.wheel_radius!r}, wheel_separation={self.wheel_separation!r})"

    def inverse(self, v: ArrayLike, omega: ArrayLike) -> tuple[Any, Any]:
        """Wheel speeds (rad/s) for a linear speed ``v`` (m/s) and yaw rate ``omega`` (rad/s).

        Scalars or broadcastable arrays; returns ``(w_left, w_right)``.
        """
        v_ = np.asarray(v, dtype=np.float64)
        omega_ = np.asarray(omega, dtype=np.float64)
        half = 0.5 * self.wheel_separation
        w_left = (v_ - half * omega_) / self.wheel_radius
        w_right = (v_ + half * omega_) / self.wheel_radius
        return _out(w_left), _out(w_right)

    def forward(self, w_left: ArrayLike, w_right: ArrayLike) -> tuple[Any, Any]:
        """``(v, omega)`` of the base for wheel speeds ``w_left``, ``w_right`` (rad/s)."""
        wl = np.asarray(w_left, dtype=np.float64)
        wr = np.asarray(w_right, dtype=np.float64)
        v = 0.5 * self.wheel_radius * (wl + wr)
        omega = self.wheel_radius * (wr - wl) / self.wheel_separation
        return _out(v), _out(omega)

    def wheel_speeds(self, body_twist: ArrayLike) -> NDArray[np.float64]:
        """``(..., 3)`` body twists ``(vx, vy, omega)`` -> ``(..., 2)`` wheel speeds; ``vy`` is ignored."""
        twist = _check_twist(body_twist)
        w_left, w_right = self.inverse(twist[..., 0], twist[..., 2])
        return np.stack([np.asarray(w_left), np.asarray(w_right)], axis=-1)

    def body_twist(self, wheel_speeds: ArrayLike) -> NDArray[np.float64]:
        """``(..., 2)`` wheel speeds -> ``(..., 3)`` body twists ``(vx, 0, omega)``."""
        wheels = _check_wheels(wheel_speeds, 2)
        v, omega = self.forward(wheels[..., 0], wheels[..., 1])
        v = np.asarray(v)
        return np.stack([v, np.zeros_like(v), np.asarray(omega)], axis=-1)


class Mecanum:
    """Four mecanum wheels with 45-degree rollers in X configuration.

    Wheel order is front-left, front-right, rear-left, rear-right. With
    ``k = half_length + half_width``::

        w_fl = (vx - vy - k*omega) / r      w_fr = (vx + vy + k*omega) / r
        w_rl = (vx + vy - k*omega) / r      w_rr = (vx - vy + k*omega) / r

    Parameters
    ----------
    wheel_radius : float
        Wheel radius in metres, > 0.
    half_length : float
        Half the wheelbase (front to rear axle) in metres, >= 0.
    half_width : float
        Half the track width (left to right wheel) in metres, >= 0; ``half_length + half_width`` > 0.
    """

    n_wheels = 4
    wheel_names = (
        "front_left_wheel_joint",
        "front_right_wheel_joint",
        "rear_left_wheel_joint",
        "rear_right_wheel_joint",
    )

    def __init__(self, wheel_radius: float, half_length: float, half_width: float) -> None:
        self.wheel_radius = check_positive("wheel_radius", wheel_radius)
        self.half_length = check_non_negative("half_length", half_length)
        self.half_width = check_non_negative("half_width", half_width)
        self.k = self.half_length + self.half_width
        if self.k <= 0.0:
            raise ValueError(
                f"half_length + half_width must be > 0, got {half_length!r} + {half_width!r}; "
                "give the wheel positions from the base centre in metres"
            )
        k = self.k
        # rows: fl, fr, rl, rr; columns: vx, vy, omega (already divided by r)
        self._wheels_from_twist = np.array(
            [[1.0, -1.0, -k], [1.0, 1.0, k], [1.0, 1.0, -k], [1.0, -1.0, k]]
        ) / self.wheel_radius
        self._twist_from_wheels = np.linalg.pinv(self._wheels_from_twist)

    def __repr__(self) -> str:
        return (
            f"Mecanum(wheel_radius={self.wheel_radius!r}, half_length={self.half_length!r}, "
            f"half_width={self.half_width!r})"
        )

    def inverse(self, vx: ArrayLike, vy: ArrayLike, omega: ArrayLike) -> tuple[Any, Any, Any, Any]:
        """Wheel speeds ``(w_fl, w_fr, w_rl, w_rr)`` in rad/s for a body twist (scalars or arrays)."""
        vx_ = np.asarray(vx, dtype=np.float64)
        vy_ = np.asarray(vy, dtype=np.float64)
        om = np.asarray(omega, dtype=np.float64) * self.k
        r = self.wheel_radius
        return (
            _out((vx_ - vy_ - om) / r),
            _out((vx_ + vy_ + om) / r),
            _out((vx_ + vy_ - om) / r),
            _out((vx_ - vy_ + om) / r),
        )

    def forward(
        self, w_fl: ArrayLike, w_fr: ArrayLike, w_rl: ArrayLike, w_rr: ArrayLike
    ) -> tuple[Any, Any, Any]:
        """Least-squares body twist ``(vx, vy, omega)`` for four wheel speeds (rad/s)."""
        fl, fr, rl, rr = (np.asarray(w, dtype=np.float64) for w in (w_fl, w_fr, w_rl, w_rr))
        q = 0.25 * self.wheel_radius
        vx = q * (fl + fr + rl + rr)
        vy = q * (-fl + fr + rl - rr)
        omega = q * (-fl + fr - rl + rr) / self.k
        return _out(vx), _out(vy), _out(omega)

    def wheel_speeds(self, body_twist: ArrayLike) -> NDArray[np.float64]:
        """``(..., 3)`` body twists -> ``(..., 4)`` wheel speeds (fl, fr, rl, rr)."""
        return _check_twist(body_twist) @ self._wheels_from_twist.T

    def body_twist(self, wheel_speeds: ArrayLike) -> NDArray[np.float64]:
        """``(..., 4)`` wheel speeds -> ``(..., 3)`` least-squares body twists."""
        return _check_wheels(wheel_speeds, 4) @ self._twist_from_wheels.T


def saturate_wheel_speeds(wheel_speeds: ArrayLike, max_wheel_speed: float) -> NDArray[np.float64]:
    """Scale all wheels by one factor so none exceeds ``max_wheel_speed`` (rad/s).

    Scaling every wheel together keeps the direction of motion (the ratio of
    vx : vy : omega) and only slows the base down, where clipping wheels one by
    one would turn it.

    Parameters
    ----------
    wheel_speeds : array_like, shape (n,) or (m, n)
        Wheel speeds in rad/s; each row is scaled on its own.
    max_wheel_speed : float
        Largest allowed absolute wheel speed, > 0.

    Returns
    -------
    ndarray, same shape as ``wheel_speeds``
    """
    limit = check_positive("max_wheel_speed", max_wheel_speed)
    wheels = np.asarray(wheel_speeds, dtype=np.float64)
    if wheels.ndim not in (1, 2):
        raise ValueError(f"wheel_speeds must have shape (n,) or (m, n), got shape {wheels.shape}")
    peak = np.max(np.abs(wheels), axis=-1, keepdims=True) if wheels.size else np.zeros(wheels.shape[:-1] + (1,))
    scale = np.where(peak > limit, limit / np.where(peak > 0.0, peak, 1.0), 1.0)
    return wheels * scale


def _check_twist(body_twist: ArrayLike) -> NDArray[np.float64]:
    twist = np.asarray(body_twist, dtype=np.float64)
    if twist.ndim == 0 or twist.shape[-1] != 3:
        raise ValueError(f"body_twist must have shape (..., 3) as (vx, vy, omega), got shape {twist.shape}")
    return twist


def _check_wheels(wheel_speeds: ArrayLike, n: int) -> NDArray[np.float64]:
    wheels = np.asarray(wheel_speeds, dtype=np.float64)
    if wheels.ndim == 0 or wheels.shape[-1] != n:
        raise ValueError(f"wheel_speeds must have shape (..., {n}), got shape {wheels.shape}")
    return wheels
