"""A PID controller with output limits, anti-windup and derivative on measurement."""

from __future__ import annotations

import math

from ._checks import check_non_negative, check_positive

__all__ = ["PID"]


class PID:
    """Discrete PID: ``u = kp*e + I - kd * d(measurement)/dt`` with ``e = setpoint - measurement``.

    - The derivative acts on the measurement, not the error, so a setpoint step
      gives no derivative kick.
    - The integral term ``I`` (stored already multiplied by ``ki``) is clamped
      to the output limits and stops growing while the output is saturated in
      the direction of the error (conditional integration): it never winds up,
      so the output leaves saturation as soon as the error changes sign.
    - The derivative can be low-pass filtered with time constant
      ``derivative_tau_sec`` (0 = unfiltered).

    Parameters
    ----------
    kp, ki, kd : float
        Gains, >= 0.
    output_limits : (float or None, float or None)
        Lower and upper output bound; ``None`` for unbounded.
    derivative_tau_sec : float
        Derivative filter time constant in seconds, >= 0.
    """

    def __init__(
        self,
        kp: float,
        ki: float = 0.0,
        kd: float = 0.0,
        *,
        output_limits: tuple[float | None, float | None] = (None, None),
        derivative_tau_sec: float = 0.0,
    ) -> None:
        self.kp = check_non_negative("kp", kp)
        self.ki = check_non_negative("ki", ki)
        self.kd = check_non_negative("kd", kd)
        low, high = output_limits
        self.output_min = -math.inf if low is None else float(low)
        self.output_max = math.inf if high is None else float(high)
        if not self.output_min < self.output_max:
            raise ValueError(
                f"output_limits must be (low, high) with low < high, got {output_limits!r}"
            )
        self.derivative_tau_sec = check_non_negative("derivative_tau_sec", derivative_tau_sec)
        self.reset()

    def __repr__(self) -> str:
        return (
            f"PID(kp={self.kp}, ki={self.ki}, kd={self.kd}, "
            f"output_limits=({self.output_min}, {self.output_max}), integral={self.integral:.4g})"
        )

    def reset(self) -> None:
        """Forget the integral, the previous measurement and the derivative filter state."""
        self.integral = 0.0
        self.derivative = 0.0
        self._last_measurement: float | None = None
        self.last_output = 0.0

    def _clamp(self, value: float) -> float:
        return min(max(value, self.output_min), self.output_max)

    def update(self, setpoint: float, measurement: float, dt_sec: float) -> float:
        """One control step; returns the output clamped to the limits.

        Parameters
        ----------
        setpoint, measurement : float
            Desired and measured value, same unit.
        dt_sec : float
            Time since the previous call, > 0.
        """
        dt = check_positive("dt_sec", dt_sec)
        error = float(setpoint) - float(measurement)
        proportional = self.kp * error

        if self._last_measurement is None or self.kd == 0.0:
            raw_derivative = 0.0
        else:
            raw_derivative = -(float(measurement) - self._last_measurement) / dt
        if self.derivative_tau_sec > 0.0:
            alpha = dt / (self.derivative_tau_sec + dt)
            self.derivative += alpha * (raw_derivative - self.derivative)
        else:
            self.derivative = raw_derivative
        self._last_measurement = float(measurement)
        derivative_term = self.kd * self.derivative

        unsaturated = proportional + self.integral + derivative_term
        pushing_up = unsaturated >= self.output_max and error > 0.0
        pushing_down = unsaturated <= self.output_min and error < 0.0
        if not (pushing_up or pushing_down):
            self.integral = self._clamp(self.integral + self.ki * error * dt)
        self.last_output = self._clamp(proportional + self.integral + derivative_term)
        return self.last_output
