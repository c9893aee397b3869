"""The 15-state UKF core: robot_localization's ``Ukf`` (ukf.cpp), on the EKF's state layout and model.

Same state members, process model (the omnidirectional transfer function) and measurement rules
as :class:`~aiorobot.fusion.Ekf`; the prediction and correction go through the unscented
transform instead of the Jacobian. ``alpha``, ``kappa`` and ``beta`` are ukf_node's parameters:
with ``n = 15`` and ``lambda = alpha^2 (n + kappa) - n``, the ``2n + 1`` sigma points are the
state and the state plus and minus the columns of the Cholesky factor of ``(n + lambda) P``;
mean weights ``lambda / (n + lambda)`` then ``1 / (2 (n + lambda))``, covariance weights the
same but the first plus ``1 - alpha^2 + beta`` (ukf.cpp ``setConstants``; filterpy's
``MerweScaledSigmaPoints``, which the tests use as the oracle).

Where it follows ukf.cpp rather than the textbook: Euler angles are averaged as circular means
and their differences wrapped; process noise is added as ``dt * Q`` after the transform; the
correction right after a prediction reuses the moved sigma points, later ones draw new points;
the covariance update is ``P -= K P_zz K^T`` (ukf.cpp's form: ``P_zz`` without the measurement
noise). One deliberate difference: ukf.cpp wraps the state difference at the measurement's
position ``i`` instead of the state member ``update_indices[i]``; here the angle members are
wrapped. The two agree whenever the sigma points spread less than pi, which ``alpha`` of 1e-3
guarantees for any covariance below 1e5.
"""

from __future__ import annotations

import math
from types import ModuleType
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ._ekf import (
    _REASONS,
    DEFAULT_PROCESS_NOISE,
    STATE_SIZE,
    Correction,
    _as_mask,
    _as_vector,
    _check_state,
    _is_float_matrix,
    check_covariance,
)

__all__ = ["Ukf", "check_ukf_constants"]

_kernels: ModuleType | None = None


def _k() -> Any:
    global _kernels
    if _kernels is None:
        from . import _ukf_kernels as kernels

        _kernels = kernels
    return _kernels


def check_ukf_constants(alpha: float, kappa: float, beta: float) -> tuple[float, float, float]:
    """``(alpha, kappa, beta)`` as floats; ``ValueError`` when they give no sigma-point spread
    (``alpha`` must be non-zero and ``n + kappa`` positive) or are not finite."""
    values = []
    for name, value in (("alpha", alpha), ("kappa", kappa), ("beta", beta)):
        v = float(value)
        if not math.isfinite(v):
            raise ValueError(f"{name}: expected a finite number, got {value!r}")
        values.append(v)
    a, k, b = values
    if a == 0.0:
        raise ValueError("alpha: expected a non-zero spread of the sigma points (ukf_node's default is 0.001), got 0")
    if STATE_SIZE + k <= 0.0:
        raise ValueError(f"kappa: expected a value above -{STATE_SIZE} (n + kappa must be positive), got {kappa!r}")
    return a, k, b


class Ukf:
    """robot_localization's ``Ukf``: the :class:`~aiorobot.fusion.Ekf` interface (``state``,
    ``covariance``, ``predict``, ``update``, ``reset``, ``snapshot``, ``restore``), unscented.

    Parameters
    ----------
    process_noise, initial_covariance, initial_state : as :class:`~aiorobot.fusion.Ekf`
    alpha, kappa, beta : float
        ukf_node's ``alpha`` (0.001), ``kappa`` (0) and ``beta`` (2).
    """

    def __init__(
        self,
        *,
        process_noise: ArrayLike | None = None,
        initial_covariance: ArrayLike | None = None,
        initial_state: ArrayLike | None = None,
        alpha: float = 0.001,
        kappa: float = 0.0,
        beta: float = 2.0,
    ) -> None:
        self.alpha, self.kappa, self.beta = check_ukf_constants(alpha, kappa, beta)
        n = STATE_SIZE
        lam = self.alpha**2 * (n + self.kappa) - n
        #: ``n + lambda``, the scale of the covariance whose square root spreads the sigma points
        self.scale = n + lam
        self.mean_weights = np.full(2 * n + 1, 1.0 / (2.0 * (n + lam)))
        self.mean_weights[0] = lam / (n + lam)
        self.covariance_weights = self.mean_weights.copy()
        self.covariance_weights[0] += 1.0 - self.alpha**2 + self.beta
        self.process_noise = (
            DEFAULT_PROCESS_NOISE.copy()
            if process_noise is None
            else check_covariance("process_noise_covariance", process_noise)
        )
        self._initial_covariance = (
            np.eye(n) * 1e-9
            if initial_covariance is None
            else check_covariance("initial_estimate_covariance", initial_covariance)
        )
        self._initial_state = np.zeros(n) if initial_state is None else _check_state("initial_state", initial_state)
        self.state = self._initial_state.copy()
        self.covariance = self._initial_covariance.copy()
        #: the sigma points (2n+1, n): after :meth:`predict`, moved by the process model
        self.sigma_points = np.zeros((2 * n + 1, n))
        self._work = np.zeros((3, n, n))
        # ukf.cpp's uncorrected_: the moved sigma points still describe (state, covariance)
        self._moved = False
        self._predicted = (np.zeros(n), np.zeros((n, n)))

    def __repr__(self) -> str:
        x, y, _, _, _, yaw = self.state[:6]
        return f"<Ukf x={x:.3f} y={y:.3f} yaw={yaw:.3f} alpha={self.alpha:g} kappa={self.kappa:g} beta={self.beta:g}>"

    @staticmethod
    def warm_up() -> None:
        """Load (or compile) the Numba kernels now, in the calling thread (see :meth:`Ekf.warm_up`)."""
        from ._ekf import Ekf

        Ekf.warm_up()
        ukf = Ukf()
        ukf.predict(0.01)
        ukf.update(np.zeros(STATE_SIZE), np.eye(STATE_SIZE), np.ones(STATE_SIZE, dtype=np.bool_))
        ukf.update(np.zeros(STATE_SIZE), np.eye(STATE_SIZE), np.ones(STATE_SIZE, dtype=np.bool_))

    def reset(self) -> None:
        """Back to the initial state and covariance."""
        self.state[:] = self._initial_state
        self.covariance[:] = self._initial_covariance
        self._moved = False

    def predict(self, dt_sec: float) -> None:
        """Propagate by ``dt_sec`` (>= 0) through the unscented transform (ukf.cpp ``predict``)."""
        dt = float(dt_sec)
        if not math.isfinite(dt) or dt < 0.0:
            raise ValueError(f"dt_sec: expected a finite value >= 0, got {dt_sec!r}")
        if dt == 0.0:
            return
        _k().predict_inplace(
            self.state, self.covariance, self.process_noise, dt, self.sigma_points,
            self.mean_weights, self.covariance_weights, self.scale, self._work,
        )  # fmt: skip
        self._moved = True
        self._predicted[0][:] = self.state
        self._predicted[1][:] = self.covariance

    def update(
        self,
        z: ArrayLike,
        R: ArrayLike,
        mask: ArrayLike,
        *,
        mahalanobis_threshold: float = math.inf,
    ) -> Correction:
        """Correct with the members of ``z`` (15,) selected by ``mask``, covariance ``R`` (15x15); the
        measurement rules of :meth:`Ekf.update <aiorobot.fusion.Ekf.update>` (NaN/inf left out,
        variances made positive and at least 1e-9, angle innovations wrapped, Mahalanobis test)."""
        zv = _as_vector(z)
        Rm = R if _is_float_matrix(R) else check_covariance("R", R)
        exact = type(mask) is np.ndarray and mask.dtype == np.bool_ and mask.shape == (STATE_SIZE,)
        mk = mask if exact else _as_mask(mask)
        threshold_sq = math.inf if mahalanobis_threshold == math.inf else float(mahalanobis_threshold) ** 2
        # the moved points serve only the state they were predicted to: not after a correction,
        # a reset, or a state written from outside (the first measurement, set_pose, a rewind)
        fresh = (
            self._moved
            and np.array_equal(self.state, self._predicted[0])
            and np.array_equal(self.covariance, self._predicted[1])
        )
        status, d2 = _k().correct_inplace(
            self.state, self.covariance, zv, Rm, mk, threshold_sq, self.sigma_points,
            self.mean_weights, self.covariance_weights, self.scale, not fresh, self._work[2],
        )  # fmt: skip
        if status == 0:
            self._moved = False
            return Correction(True, d2)
        return Correction(False, d2, _REASONS[status])

    def snapshot(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Copies of ``(state, covariance)``."""
        return self.state.copy(), self.covariance.copy()

    def restore(self, state: NDArray[np.float64], covariance: NDArray[np.float64]) -> None:
        self.state[:] = state
        self.covariance[:] = covariance
        self._moved = False
