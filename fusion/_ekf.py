"""The 15-state EKF core: robot_localization's state layout, motion model and correction, no node.

State members (robot_localization's ``StateMembers``, same order)::

    0 x   1 y   2 z   3 roll   4 pitch   5 yaw   6 vx   7 vy   8 vz
    9 vroll   10 vpitch   11 vyaw   12 ax   13 ay   14 az

Positions and orientation are in the world frame; velocities and accelerations in the body frame.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from types import ModuleType
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "STATE_SIZE",
    "STATE_NAMES",
    "DEFAULT_PROCESS_NOISE",
    "Correction",
    "Ekf",
    "force_two_d",
    "check_covariance",
]

STATE_SIZE = 15
STATE_NAMES = (
    "x", "y", "z", "roll", "pitch", "yaw", "vx", "vy", "vz",
    "vroll", "vpitch", "vyaw", "ax", "ay", "az",
)  # fmt: skip
#: robot_localization's FilterBase defaults (filter_base.cpp), per second.
DEFAULT_PROCESS_NOISE = np.diag(
    [0.05, 0.05, 0.06, 0.03, 0.03, 0.06, 0.025, 0.025, 0.04, 0.01, 0.01, 0.02, 0.01, 0.01, 0.015]
)
_THREE_D_INDEX = np.array([2, 3, 4, 8, 9, 10, 14])  # z roll pitch vz vroll vpitch az

_kernels: ModuleType | None = None


def _k() -> Any:
    global _kernels
    if _kernels is None:
        from . import _kernels as kernels

        _kernels = kernels
    return _kernels


def check_covariance(name: str, value: ArrayLike, size: int = STATE_SIZE) -> NDArray[np.float64]:
    """Coerce to a float64 ``(size, size)`` matrix; a flat list of ``size**2`` (ROS row-major) is accepted."""
    arr = np.asarray(value, dtype=np.float64)
    if arr.shape == (size * size,):
        arr = arr.reshape(size, size)
    elif arr.shape == (size,):
        arr = np.diag(arr)
    if arr.shape != (size, size):
        raise ValueError(
            f"{name}: expected a {size}x{size} matrix, {size * size} values row-major or {size} diagonal "
            f"values, got shape {arr.shape}"
        )
    return np.ascontiguousarray(arr)


def _check_state(name: str, value: ArrayLike) -> NDArray[np.float64]:
    arr = np.array(value, dtype=np.float64).reshape(-1)
    if arr.shape != (STATE_SIZE,):
        raise ValueError(f"{name}: expected {STATE_SIZE} values, got shape {arr.shape}")
    return arr


_REASONS = {
    1: "no finite member selected",
    2: "covariance is not finite",
    3: "innovation covariance is singular",
    4: "Mahalanobis distance over the rejection threshold",
}


def _is_float_matrix(a: object) -> bool:
    return type(a) is np.ndarray and a.dtype == np.float64 and a.shape == (STATE_SIZE, STATE_SIZE)  # type: ignore[union-attr]


def _as_vector(z: ArrayLike) -> NDArray[np.float64]:
    if type(z) is np.ndarray and z.dtype == np.float64 and z.shape == (STATE_SIZE,):
        return z
    return _check_state("z", z)


def _as_mask(mask: ArrayLike) -> NDArray[np.bool_]:
    mk = np.asarray(mask, dtype=bool).reshape(-1)
    if mk.shape != (STATE_SIZE,):
        raise ValueError(f"mask: expected {STATE_SIZE} booleans, got shape {mk.shape}")
    return mk


def force_two_d(
    z: NDArray[np.float64], R: NDArray[np.float64], mask: NDArray[np.bool_]
) -> None:
    """robot_localization's ``forceTwoD``: measure z, roll, pitch, vz, vroll, vpitch, az as 0 (var 1e-6)."""
    z[_THREE_D_INDEX] = 0.0
    R[_THREE_D_INDEX, :] = 0.0
    R[:, _THREE_D_INDEX] = 0.0
    R[_THREE_D_INDEX, _THREE_D_INDEX] = 1e-6
    mask[_THREE_D_INDEX] = True


@dataclass(frozen=True)
class Correction:
    """Outcome of :meth:`Ekf.update`: accepted or rejected, and the squared Mahalanobis distance."""

    accepted: bool
    mahalanobis_sq: float
    reason: str = ""


class Ekf:
    """robot_localization's ``Ekf``: omnidirectional 3D model, Joseph-form correction.

    Parameters
    ----------
    process_noise : array_like, shape (15, 15), optional
        Process noise per second (``process_noise_covariance``); scaled by ``dt`` in :meth:`predict`.
    initial_covariance : array_like, shape (15, 15), optional
        ``initial_estimate_covariance``; default ``1e-9`` on the diagonal.
    initial_state : array_like, shape (15,), optional
    """

    def __init__(
        self,
        *,
        process_noise: ArrayLike | None = None,
        initial_covariance: ArrayLike | None = None,
        initial_state: ArrayLike | None = None,
    ) -> None:
        self.process_noise = (
            DEFAULT_PROCESS_NOISE.copy()
            if process_noise is None
            else check_covariance("process_noise_covariance", process_noise)
        )
        self._initial_covariance = (
            np.eye(STATE_SIZE) * 1e-9
            if initial_covariance is None
            else check_covariance("initial_estimate_covariance", initial_covariance)
        )
        self._initial_state = (
            np.zeros(STATE_SIZE) if initial_state is None else _check_state("initial_state", initial_state)
        )
        self.state = self._initial_state.copy()
        self.covariance = self._initial_covariance.copy()
        self._work = np.zeros((3, STATE_SIZE, STATE_SIZE))

    def __repr__(self) -> str:
        x, y, _, _, _, yaw = self.state[:6]
        return f"<Ekf x={x:.3f} y={y:.3f} yaw={yaw:.3f}>"

    @staticmethod
    def warm_up() -> None:
        """Load (or compile) the Numba kernels now, in the calling thread.

        A kernel's first call imports Numba and reads its cache, tens of milliseconds; a node
        calls this at construction so that cost never lands on the loop it runs on (the
        priority loop, where it would be a stall).
        """
        from ._kernels import covariance_status

        ekf = Ekf()
        ekf.predict(0.01)
        ekf.update(np.zeros(STATE_SIZE), np.eye(STATE_SIZE), np.ones(STATE_SIZE, dtype=np.bool_))
        for size in (3, 6):
            covariance_status(np.eye(size))

    def reset(self) -> None:
        """Back to the initial state and covariance."""
        self.state[:] = self._initial_state
        self.covariance[:] = self._initial_covariance

    def predict(self, dt_sec: float) -> None:
        """Propagate by ``dt_sec`` (>= 0): ``x <- f(x)``, ``P <- J P J^T + dt Q`` (ekf.cpp ``predict``)."""
        dt = float(dt_sec)
        if not math.isfinite(dt) or dt < 0.0:
            raise ValueError(f"dt_sec: expected a finite value >= 0, got {dt_sec!r}")
        if dt == 0.0:
            return
        _k().predict_inplace(self.state, self.covariance, self.process_noise, dt, self._work)

    def update(
        self,
        z: ArrayLike,
        R: ArrayLike,
        mask: ArrayLike,
        *,
        mahalanobis_threshold: float = math.inf,
    ) -> Correction:
        """Correct with the members of ``z`` (15,) selected by ``mask`` (15 bools), covariance ``R`` (15x15).

        As in ekf.cpp ``correct``: NaN/inf members are left out, negative variances use their absolute
        value, variances below 1e-9 are raised to 1e-9, angle innovations are wrapped, and a
        measurement whose squared Mahalanobis distance is >= ``mahalanobis_threshold**2`` is rejected.
        """
        zv = _as_vector(z)
        Rm = R if _is_float_matrix(R) else check_covariance("R", R)
        mk = mask if (type(mask) is np.ndarray and mask.dtype == np.bool_ and mask.shape == (STATE_SIZE,)) else _as_mask(mask)
        threshold_sq = math.inf if mahalanobis_threshold == math.inf else float(mahalanobis_threshold) ** 2
        status, d2 = _k().correct_inplace(self.state, self.covariance, zv, Rm, mk, threshold_sq)
        if status == 0:
            return Correction(True, d2)
        return Correction(False, d2, _REASONS[status])

    def snapshot(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Copies of ``(state, covariance)``."""
        return self.state.copy(), self.covariance.copy()

    def restore(self, state: NDArray[np.float64], covariance: NDArray[np.float64]) -> None:
        self.state[:] = state
        self.covariance[:] = covariance
