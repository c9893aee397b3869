"""Velocity smoother: per-axis velocity, acceleration and deceleration limits."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ._checks import check_limits, check_non_negative, check_vector

__all__ = ["VelocitySmoother"]


class VelocitySmoother:
    """Limits a commanded body twist ``(vx, vy, omega)`` axis by axis.

    Each step the target is clipped to ``±max_velocity`` and the change from the
    previous output to at most ``max_acceleration * dt`` (speeding up) or
    ``max_deceleration * dt`` (slowing down, including through zero).

    Parameters
    ----------
    max_velocity : float or array_like, shape (3,)
        Per-axis absolute velocity limit (m/s, m/s, rad/s); ``inf`` for none.
    max_acceleration : float or array_like, shape (3,)
        Per-axis limit on speeding up (m/s^2, m/s^2, rad/s^2).
    max_deceleration : float or array_like, shape (3,), optional
        Per-axis limit on slowing down; defaults to ``max_acceleration``.
    """

    def __init__(
        self,
        max_velocity: ArrayLike,
        max_acceleration: ArrayLike,
        max_deceleration: ArrayLike | None = None,
    ) -> None:
        self.max_velocity = check_limits("max_velocity", max_velocity, 3)
        self.max_acceleration = check_limits("max_acceleration", max_acceleration, 3)
        self.max_deceleration = (
            self.max_acceleration.copy()
            if max_deceleration is None
            else check_limits("max_deceleration", max_deceleration, 3)
        )
        self.velocity = np.zeros(3)

    def __repr__(self) -> str:
        return (
            f"VelocitySmoother(max_velocity={self.max_velocity.tolist()}, "
            f"max_acceleration={self.max_acceleration.tolist()}, velocity={self.velocity.tolist()})"
        )

    def reset(self, velocity: ArrayLike = (0.0, 0.0, 0.0)) -> None:
        """Set the current output velocity (default: standing still)."""
        self.velocity = check_vector("velocity", velocity, 3).copy()

    def update(self, target: ArrayLike, dt_sec: float) -> NDArray[np.float64]:
        """Move the output toward ``target`` (shape (3,)) within the limits; returns the new output."""
        goal = np.clip(check_vector("target", target, 3), -self.max_velocity, self.max_velocity)
        dt = check_non_negative("dt_sec", dt_sec)
        current = self.velocity
        change = goal - current
        # slowing down: the change points against the current velocity
        slowing = (current * change) < 0.0
        rate = np.where(slowing, self.max_deceleration, self.max_acceleration)
        step = np.clip(change, -rate * dt, rate * dt)
        # when the limited step crosses zero, the part past zero is speeding up again
        crossed = slowing & (np.abs(step) > np.abs(current))
        if np.any(crossed):
            time_to_zero = np.abs(current) / np.where(self.max_deceleration > 0, self.max_deceleration, 1.0)
            remaining = np.maximum(dt - time_to_zero, 0.0)
            beyond = np.clip(goal, -self.max_acceleration * remaining, self.max_acceleration * remaining)
            step = np.where(crossed, beyond - current, step)
        self.velocity = current + step
        return self.velocity.copy()
