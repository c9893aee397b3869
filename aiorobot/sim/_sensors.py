"""Sensor models: pure classes on numpy arrays, each with its own seeded noise.

Every ``measure`` takes the ground truth and a ``numpy.random.Generator`` and
returns what the sensor reports; nothing here knows about topics or time.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ._raycast import raycast
from ._world import World

__all__ = ["GRAVITY", "ImuModel", "LidarModel"]

#: Standard gravity (m/s^2); a level accelerometer at rest reads +GRAVITY on z.
GRAVITY = 9.80665


def _non_negative(name: str, value: float) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not value >= 0:
        raise ValueError(f"{name}: expected a number >= 0, found {value!r}")
    return float(value)


@dataclass(frozen=True)
class LidarModel:
    """A 2D scanner: ``beams`` rays over a full turn from ``-pi``, Gaussian range noise.

    Readings follow REP 117: ``inf`` for no return within ``range_max``, ``-inf``
    closer than ``range_min``.
    """

    beams: int = 360
    range_min: float = 0.1
    range_max: float = 12.0
    noise_std: float = 0.01

    def __post_init__(self) -> None:
        object.__setattr__(self, "_angles", self.angle_min + self.angle_increment * np.arange(self.beams))
        if isinstance(self.beams, bool) or not isinstance(self.beams, int) or self.beams <= 0:
            raise ValueError(f"beams: expected an int > 0, found {self.beams!r}")
        _non_negative("scan_noise_std", self.noise_std)
        if not 0 <= self.range_min < self.range_max:
            raise ValueError(f"range_min/range_max: expected 0 <= min < max, found {self.range_min!r}, {self.range_max!r}")

    @property
    def angle_min(self) -> float:
        return -math.pi

    @property
    def angle_increment(self) -> float:
        return 2.0 * math.pi / self.beams

    @property
    def angles(self) -> NDArray[np.float64]:
        """Beam angles in the laser frame, shape (beams,)."""
        return self._angles.copy()

    def measure(self, world: World, x: float, y: float, yaw: float, rng: np.random.Generator) -> NDArray[np.float32]:
        """Ranges (m, float32) seen from a laser at ``(x, y)`` looking along ``yaw``."""
        ranges = raycast(world.occupied, world.resolution, world.origin[:2], (x, y), self._angles + yaw, self.range_max,
                         clearance=world.clearance)
        if self.noise_std > 0.0:
            ranges += rng.normal(0.0, self.noise_std, ranges.shape[0])  # inf stays inf
        ranges[ranges > self.range_max] = np.inf
        ranges[ranges < self.range_min] = -np.inf
        return ranges.astype(np.float32)


class ImuModel:
    """A planar IMU: gyro with a constant bias, a bias random walk and white noise; accelerometer with gravity.

    Parameters
    ----------
    gyro_noise_std : float
        White noise on each gyro axis (rad/s).
    gyro_bias_std : float
        Standard deviation of the initial gyro bias (rad/s), drawn once.
    gyro_bias_walk_std : float
        Random-walk rate of the bias (rad/s per sqrt(s)).
    accel_noise_std : float
        White noise on each accelerometer axis (m/s^2).
    rng : numpy.random.Generator
    """

    def __init__(self, *, gyro_noise_std: float = 0.002, gyro_bias_std: float = 0.001,
                 gyro_bias_walk_std: float = 0.0001, accel_noise_std: float = 0.02,
                 rng: np.random.Generator) -> None:
        self.gyro_noise_std = _non_negative("gyro_noise_std", gyro_noise_std)
        self.gyro_bias_std = _non_negative("gyro_bias_std", gyro_bias_std)
        self.gyro_bias_walk_std = _non_negative("gyro_bias_walk_std", gyro_bias_walk_std)
        self.accel_noise_std = _non_negative("accel_noise_std", accel_noise_std)
        self.rng = rng
        self.gyro_bias = rng.normal(0.0, self.gyro_bias_std, 3) if self.gyro_bias_std > 0 else np.zeros(3)

    def __repr__(self) -> str:
        return f"<ImuModel gyro_bias={np.round(self.gyro_bias, 5).tolist()} rad/s>"

    def measure(self, omega_z: float, accel_xy: NDArray[np.float64], dt_sec: float) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """``(angular_velocity, linear_acceleration)``, both shape (3,), for a level body.

        ``dt_sec`` is the time since the previous measurement (drives the bias walk).
        """
        rng = self.rng
        if self.gyro_bias_walk_std > 0.0 and dt_sec > 0.0:
            self.gyro_bias = self.gyro_bias + rng.normal(0.0, self.gyro_bias_walk_std * math.sqrt(dt_sec), 3)
        gyro = np.array([0.0, 0.0, omega_z]) + self.gyro_bias
        if self.gyro_noise_std > 0.0:
            gyro = gyro + rng.normal(0.0, self.gyro_noise_std, 3)
        accel = np.array([accel_xy[0], accel_xy[1], GRAVITY])
        if self.accel_noise_std > 0.0:
            accel = accel + rng.normal(0.0, self.accel_noise_std, 3)
        return gyro, accel
