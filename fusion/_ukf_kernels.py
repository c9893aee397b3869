"""Numba kernels of the 15-state UKF: robot_localization's ``Ukf`` (ukf.cpp) on the EKF's model.

Imported lazily by :mod:`aiorobot.fusion._ukf`. The process model is the EKF's transfer function
(:func:`aiorobot.fusion._kernels.transfer`), applied to each sigma point as ukf.cpp's
``projectSigmaPoint`` does.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from ._kernels import _invert, _wrap, transfer, wrap_angles_inplace

__all__ = ["correct_inplace", "predict_inplace", "sigma_points_inplace"]

_N = 15


@numba.njit(cache=True, nogil=True)
def _is_angle(i: int) -> bool:
    return 3 <= i <= 5


@numba.njit(cache=True, nogil=True)
def sigma_points_inplace(x: np.ndarray, P: np.ndarray, scale: float, sigmas: np.ndarray, L: np.ndarray) -> bool:
    """``sigmas`` (2n+1, n): ``x``, then ``x`` plus and minus each column of the lower Cholesky
    factor of ``scale * P`` (ukf.cpp ``generateSigmaPoints``, ``scale = n + lambda``).

    Returns False when ``scale * P`` is not positive definite; a non-positive pivot then leaves
    its column zero (Eigen's LLT would leave it undefined).
    """
    ok = True
    L[:, :] = 0.0
    for j in range(_N):
        s = scale * P[j, j]
        for k in range(j):
            s -= L[j, k] * L[j, k]
        if s <= 0.0:
            ok = False
            continue
        d = math.sqrt(s)
        L[j, j] = d
        for i in range(j + 1, _N):
            t = scale * P[i, j]
            for k in range(j):
                t -= L[i, k] * L[j, k]
            L[i, j] = t / d
    for i in range(_N):
        sigmas[0, i] = x[i]
    for c in range(_N):
        for i in range(_N):
            sigmas[1 + c, i] = x[i] + L[i, c]
            sigmas[1 + _N + c, i] = x[i] - L[i, c]
    return ok


@numba.njit(cache=True, nogil=True)
def predict_inplace(
    x: np.ndarray,
    P: np.ndarray,
    Q: np.ndarray,
    dt: float,
    sigmas: np.ndarray,
    wm: np.ndarray,
    wc: np.ndarray,
    scale: float,
    work: np.ndarray,
) -> bool:
    """ukf.cpp ``predict``: sigma points from ``x``/``P``, each moved by the transfer function, the
    weighted mean (Euler angles as circular means), ``P = sum wc d d^T + dt Q`` with wrapped angle
    differences, angles wrapped. ``sigmas`` keeps the moved points; ``work`` is (3, 15, 15) scratch.
    Returns the Cholesky flag of :func:`sigma_points_inplace`."""
    T = work[0]
    J = work[1]
    ok = sigma_points_inplace(x, P, scale, sigmas, work[2])
    moved = np.empty(_N)
    count = sigmas.shape[0]
    for s in range(count):
        transfer(sigmas[s], dt, T, J)
        for i in range(_N):
            acc = 0.0
            for k in range(_N):
                acc += T[i, k] * sigmas[s, k]
            moved[i] = acc
        for i in range(_N):
            sigmas[s, i] = moved[i]
    for i in range(_N):
        acc = 0.0
        for s in range(count):
            acc += wm[s] * sigmas[s, i]
        x[i] = acc
    for i in range(3, 6):
        sx = 0.0
        sy = 0.0
        for s in range(count):
            sx += wm[s] * math.cos(sigmas[s, i])
            sy += wm[s] * math.sin(sigmas[s, i])
        x[i] = math.atan2(sy, sx)
    d = np.empty(_N)
    for i in range(_N):
        for j in range(_N):
            P[i, j] = dt * Q[i, j]
    for s in range(count):
        for i in range(_N):
            d[i] = sigmas[s, i] - x[i]
            if _is_angle(i):
                d[i] = _wrap(d[i])
        w = wc[s]
        for i in range(_N):
            wi = w * d[i]
            for j in range(_N):
                P[i, j] += wi * d[j]
    wrap_angles_inplace(x)
    return ok


@numba.njit(cache=True, nogil=True)
def correct_inplace(
    x: np.ndarray,
    P: np.ndarray,
    z: np.ndarray,
    R: np.ndarray,
    mask: np.ndarray,
    threshold_sq: float,
    sigmas: np.ndarray,
    wm: np.ndarray,
    wc: np.ndarray,
    scale: float,
    regenerate: bool,
    L: np.ndarray,
) -> tuple[int, float]:
    """ukf.cpp ``correct`` with the finite members of ``z`` selected by ``mask``.

    ``regenerate``: draw the sigma points from ``x``/``P`` first (ukf.cpp does after a correction;
    right after a prediction it reuses the moved points). Predicted measurement as the weighted
    mean (circular for angles), ``P_zz`` and ``P_xz`` from wrapped differences, ``K = P_xz
    (P_zz + R)^-1``, Mahalanobis test on ``(P_zz + R)``, ``x += K nu``, ``P -= K P_zz K^T`` (ukf.cpp's
    form), angles wrapped. Status codes as the EKF's ``correct_inplace`` (0 applied, 1 nothing
    selected, 2 covariance not finite, 3 singular, 4 over the threshold).
    """
    m = 0
    for i in range(_N):
        if mask[i] and math.isfinite(z[i]):
            m += 1
    if m == 0:
        return 1, 0.0
    idx = np.empty(m, np.int64)
    m = 0
    for i in range(_N):
        if mask[i] and math.isfinite(z[i]):
            idx[m] = i
            m += 1
    for a in range(m):
        for b in range(m):
            if not math.isfinite(R[idx[a], idx[b]]):
                return 2, math.inf
    if regenerate:
        sigma_points_inplace(x, P, scale, sigmas, L)
    count = sigmas.shape[0]
    Rs = np.empty((m, m))
    for a in range(m):
        for b in range(m):
            Rs[a, b] = R[idx[a], idx[b]]
        if Rs[a, a] < 0.0:
            Rs[a, a] = -Rs[a, a]
        if Rs[a, a] < 1e-9:
            Rs[a, a] = 1e-9
    zhat = np.empty(m)
    for a in range(m):
        ia = idx[a]
        if _is_angle(ia):
            sx = 0.0
            sy = 0.0
            for s in range(count):
                sx += wm[s] * math.cos(sigmas[s, ia])
                sy += wm[s] * math.sin(sigmas[s, ia])
            zhat[a] = math.atan2(sy, sx)
        else:
            acc = 0.0
            for s in range(count):
                acc += wm[s] * sigmas[s, ia]
            zhat[a] = acc
    Pzz = np.zeros((m, m))
    Pxz = np.zeros((_N, m))
    dz = np.empty(m)
    dx = np.empty(_N)
    for s in range(count):
        for a in range(m):
            dz[a] = sigmas[s, idx[a]] - zhat[a]
            if _is_angle(idx[a]):
                dz[a] = _wrap(dz[a])
        for i in range(_N):
            dx[i] = sigmas[s, i] - x[i]
            if _is_angle(i):
                dx[i] = _wrap(dx[i])
        w = wc[s]
        for a in range(m):
            for b in range(m):
                Pzz[a, b] += w * dz[a] * dz[b]
        for i in range(_N):
            for b in range(m):
                Pxz[i, b] += w * dx[i] * dz[b]
    S = Pzz + Rs
    Sinv, ok = _invert(S)
    if not ok:
        return 3, math.inf
    nu = np.empty(m)
    for a in range(m):
        nu[a] = z[idx[a]] - zhat[a]
        if _is_angle(idx[a]):
            nu[a] = _wrap(nu[a])
    d2 = 0.0
    for a in range(m):
        acc = 0.0
        for b in range(m):
            acc += Sinv[a, b] * nu[b]
        d2 += nu[a] * acc
    if not (d2 < threshold_sq):
        return 4, d2
    K = np.zeros((_N, m))
    for i in range(_N):
        for b in range(m):
            acc = 0.0
            for a in range(m):
                acc += Pxz[i, a] * Sinv[a, b]
            K[i, b] = acc
    for i in range(_N):
        acc = 0.0
        for a in range(m):
            acc += K[i, a] * nu[a]
        x[i] += acc
    KP = np.zeros((_N, m))
    for i in range(_N):
        for b in range(m):
            acc = 0.0
            for a in range(m):
                acc += K[i, a] * Pzz[a, b]
            KP[i, b] = acc
    for i in range(_N):
        for j in range(_N):
            acc = 0.0
            for b in range(m):
                acc += KP[i, b] * K[j, b]
            P[i, j] -= acc
    wrap_angles_inplace(x)
    return 0, d2
