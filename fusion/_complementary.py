"""Complementary filter: gyro integrated, blended with accelerometer roll/pitch and odometry yaw."""

from __future__ import annotations

import math

__all__ = ["ComplementaryEstimator", "MAX_DT_SEC"]

#: a step longer than this (a gap in the IMU stream) integrates only this long, as in the seed
MAX_DT_SEC = 0.1
_TWO_PI = 2.0 * math.pi


def _wrap(a: float) -> float:
    return (a + math.pi) % _TWO_PI - math.pi


class ComplementaryEstimator:
    """Roll, pitch, yaw from a gyro, an accelerometer and (optionally) odometry yaw.

    Each IMU step integrates the body rates for ``dt = clamp(stamp - last_stamp, 0, 0.1)`` and pulls
    the result toward the reference by ``1 - alpha``: roll and pitch toward the accelerometer's
    gravity direction (when it reads 0.5 g to 1.5 g), yaw toward the latest odometry yaw (when any).

    Parameters
    ----------
    alpha : float
        Weight of the integrated gyro, in [0, 1]; default 0.98.
    """

    def __init__(self, alpha: float = 0.98) -> None:
        alpha = float(alpha)
        if not 0.0 <= alpha <= 1.0:
            raise ValueError(f"alpha: expected a value in [0, 1], got {alpha!r}")
        self.alpha = alpha
        self.roll = 0.0
        self.pitch = 0.0
        self.yaw = 0.0
        self.last_stamp_sec: float | None = None
        self.odom_yaw: float | None = None
        self.steps = 0
        self.rejected = 0

    def __repr__(self) -> str:
        return f"<ComplementaryEstimator alpha={self.alpha} rpy=({self.roll:.3f}, {self.pitch:.3f}, {self.yaw:.3f})>"

    def set_odometry_yaw(self, yaw: float) -> None:
        if math.isfinite(yaw):
            self.odom_yaw = _wrap(yaw)

    def step(
        self, stamp_sec: float, gx: float, gy: float, gz: float, ax: float, ay: float, az: float
    ) -> tuple[float, float, float]:
        """One IMU sample (rad/s, m/s^2, stamp from its header); returns ``(roll, pitch, yaw)``.

        A sample with a non-finite value is skipped (counted in ``rejected``).
        """
        if not (math.isfinite(gx) and math.isfinite(gy) and math.isfinite(gz) and math.isfinite(stamp_sec)):
            self.rejected += 1
            return self.roll, self.pitch, self.yaw
        last = self.last_stamp_sec
        dt = 0.0 if last is None else min(max(stamp_sec - last, 0.0), MAX_DT_SEC)
        if last is None or stamp_sec > last:
            self.last_stamp_sec = stamp_sec
        alpha = self.alpha
        roll, pitch = self.roll, self.pitch
        # body rates -> Euler rates (robot_localization's transfer function rows)
        sr, cr = math.sin(roll), math.cos(roll)
        cp = math.cos(pitch)
        tp = math.tan(pitch)
        roll_rate = gx + (sr * gy + cr * gz) * tp
        pitch_rate = cr * gy - sr * gz
        yaw_rate = (sr * gy + cr * gz) / cp
        roll += roll_rate * dt
        pitch += pitch_rate * dt
        yaw = self.yaw + yaw_rate * dt
        norm = math.sqrt(ax * ax + ay * ay + az * az) if math.isfinite(ax + ay + az) else 0.0
        if 4.9 <= norm <= 14.7:
            roll += (1.0 - alpha) * _wrap(math.atan2(ay, az) - roll)
            pitch += (1.0 - alpha) * (math.atan2(-ax, math.sqrt(ay * ay + az * az)) - pitch)
        if self.odom_yaw is not None:
            yaw += (1.0 - alpha) * _wrap(self.odom_yaw - yaw)
        self.roll, self.pitch, self.yaw = _wrap(roll), pitch, _wrap(yaw)
        self.steps += 1
        return self.roll, self.pitch, self.yaw
