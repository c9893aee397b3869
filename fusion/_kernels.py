"""Numba kernels of the 15-state EKF: robot_localization's omnidirectional model and correction.

Imported lazily by :mod:`aiorobot.fusion._ekf` (numba costs ~0.3 s to import). Every kernel works
in place on float64 arrays; none allocates more than the small per-update temporaries.
"""

from __future__ import annotations

import math

import numba
import numpy as np

__all__ = ["predict_inplace", "correct_inplace", "transfer", "wrap_angles_inplace"]

_ANGLES = (3, 4, 5)


@numba.njit(cache=True, nogil=True)
def _wrap(a: float) -> float:
    # robot_localization's angles::normalize_angle, into [-pi, pi)
    return (a + math.pi) % (2.0 * math.pi) - math.pi


@numba.njit(cache=True, nogil=True)
def wrap_angles_inplace(x: np.ndarray) -> None:
    for i in range(3, 6):
        x[i] = _wrap(x[i])


@numba.njit(cache=True, nogil=True)
def transfer(x: np.ndarray, dt: float, T: np.ndarray, J: np.ndarray) -> None:
    """Fill the transfer function ``T`` and its Jacobian ``J`` (15x15) at state ``x`` (ekf.cpp)."""
    roll, pitch, yaw = x[3], x[4], x[5]
    vx, vy, vz = x[6], x[7], x[8]
    vpitch, vyaw = x[10], x[11]
    axx, ayy, azz = x[12], x[13], x[14]
    sp, cp = math.sin(pitch), math.cos(pitch)
    cpi = 1.0 / cp
    tp = sp * cpi
    sr, cr = math.sin(roll), math.cos(roll)
    sy, cy = math.sin(yaw), math.cos(yaw)
    T[:, :] = 0.0
    for i in range(15):
        T[i, i] = 1.0
    T[0, 6] = cy * cp * dt
    T[0, 7] = (cy * sp * sr - sy * cr) * dt
    T[0, 8] = (cy * sp * cr + sy * sr) * dt
    T[1, 6] = sy * cp * dt
    T[1, 7] = (sy * sp * sr + cy * cr) * dt
    T[1, 8] = (sy * sp * cr - cy * sr) * dt
    T[2, 6] = -sp * dt
    T[2, 7] = cp * sr * dt
    T[2, 8] = cp * cr * dt
    for r in range(3):
        for c in range(3):
            T[r, 12 + c] = 0.5 * T[r, 6 + c] * dt
    T[3, 9] = dt
    T[3, 10] = sr * tp * dt
    T[3, 11] = cr * tp * dt
    T[4, 10] = cr * dt
    T[4, 11] = -sr * dt
    T[5, 10] = sr * cpi * dt
    T[5, 11] = cr * cpi * dt
    T[6, 12] = dt
    T[7, 13] = dt
    T[8, 14] = dt
    h = 0.5 * dt * dt
    J[:, :] = T
    yc = cy * sp * cr + sy * sr
    zc = -cy * sp * sr + sy * cr
    J[0, 3] = (yc * vy + zc * vz) * dt + (yc * ayy + zc * azz) * h
    xc, yc, zc = -cy * sp, cy * cp * sr, cy * cp * cr
    J[0, 4] = (xc * vx + yc * vy + zc * vz) * dt + (xc * axx + yc * ayy + zc * azz) * h
    xc, yc, zc = -sy * cp, -sy * sp * sr - cy * cr, -sy * sp * cr + cy * sr
    J[0, 5] = (xc * vx + yc * vy + zc * vz) * dt + (xc * axx + yc * ayy + zc * azz) * h
    yc, zc = sy * sp * cr - cy * sr, -sy * sp * sr - cy * cr
    J[1, 3] = (yc * vy + zc * vz) * dt + (yc * ayy + zc * azz) * h
    xc, yc, zc = -sy * sp, sy * cp * sr, sy * cp * cr
    J[1, 4] = (xc * vx + yc * vy + zc * vz) * dt + (xc * axx + yc * ayy + zc * azz) * h
    xc, yc, zc = cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr
    J[1, 5] = (xc * vx + yc * vy + zc * vz) * dt + (xc * axx + yc * ayy + zc * azz) * h
    yc, zc = cp * cr, -cp * sr
    J[2, 3] = (yc * vy + zc * vz) * dt + (yc * ayy + zc * azz) * h
    xc, yc, zc = -cp, -sp * sr, -sp * cr
    J[2, 4] = (xc * vx + yc * vy + zc * vz) * dt + (xc * axx + yc * ayy + zc * azz) * h
    J[3, 3] = 1.0 + (cr * tp * vpitch - sr * tp * vyaw) * dt
    J[3, 4] = (cpi * cpi * sr * vpitch + cpi * cpi * cr * vyaw) * dt
    J[4, 3] = (-sr * vpitch - cr * vyaw) * dt
    J[5, 3] = (cr * cpi * vpitch - sr * cpi * vyaw) * dt
    J[5, 4] = (sr * tp * cpi * vpitch + cr * tp * cpi * vyaw) * dt


@numba.njit(cache=True, nogil=True)
def predict_inplace(x: np.ndarray, P: np.ndarray, Q: np.ndarray, dt: float, work: np.ndarray) -> None:
    """``x <- T(x) x``; ``P <- J P J^T + dt Q``; angles wrapped. ``work`` is (3, 15, 15) scratch."""
    T = work[0]
    J = work[1]
    tmp = work[2]
    transfer(x, dt, T, J)
    xn = np.zeros(15)
    for i in range(15):
        s = 0.0
        for k in range(15):
            s += T[i, k] * x[k]
        xn[i] = s
    x[:] = xn
    wrap_angles_inplace(x)
    # tmp = J P ; J is sparse-ish but a dense product is cheap at 15x15
    for i in range(15):
        for j in range(15):
            s = 0.0
            for k in range(15):
                jik = J[i, k]
                if jik != 0.0:
                    s += jik * P[k, j]
            tmp[i, j] = s
    for i in range(15):
        for j in range(15):
            s = 0.0
            for k in range(15):
                jjk = J[j, k]
                if jjk != 0.0:
                    s += tmp[i, k] * jjk
            P[i, j] = s + dt * Q[i, j]


@numba.njit(cache=True, nogil=True)
def _invert(S: np.ndarray) -> tuple[np.ndarray, bool]:
    """Gauss-Jordan inverse with partial pivoting; ``ok`` False when singular."""
    n = S.shape[0]
    A = S.copy()
    inv = np.eye(n)
    for c in range(n):
        p = c
        best = abs(A[c, c])
        for r in range(c + 1, n):
            if abs(A[r, c]) > best:
                best = abs(A[r, c])
                p = r
        if best < 1e-300 or not math.isfinite(best):
            return inv, False
        if p != c:
            for k in range(n):
                A[c, k], A[p, k] = A[p, k], A[c, k]
                inv[c, k], inv[p, k] = inv[p, k], inv[c, k]
        d = 1.0 / A[c, c]
        for k in range(n):
            A[c, k] *= d
            inv[c, k] *= d
        for r in range(n):
            if r != c:
                f = A[r, c]
                if f != 0.0:
                    for k in range(n):
                        A[r, k] -= f * A[c, k]
                        inv[r, k] -= f * inv[c, k]
    return inv, True


@numba.njit(cache=True, nogil=True)
def correct_inplace(
    x: np.ndarray, P: np.ndarray, z: np.ndarray, R: np.ndarray, mask: np.ndarray, threshold_sq: float
) -> tuple[int, float]:
    """Correct with the finite members of ``z`` selected by ``mask``, covariance ``R[idx][:, idx]``.

    Joseph-form covariance update as in ekf.cpp. Returns ``(status, squared Mahalanobis distance)``:
    0 applied; 1 no finite member selected; 2 covariance not finite; 3 innovation covariance
    singular; 4 distance >= ``threshold_sq`` (state untouched unless 0).
    """
    m = 0
    for i in range(15):
        if mask[i] and math.isfinite(z[i]):
            m += 1
    if m == 0:
        return 1, 0.0
    idx = np.empty(m, np.int64)
    m = 0
    for i in range(15):
        if mask[i] and math.isfinite(z[i]):
            idx[m] = i
            m += 1
    for a in range(m):
        for b in range(m):
            if not math.isfinite(R[idx[a], idx[b]]):
                return 2, math.inf
    S = np.empty((m, m))
    nu = np.empty(m)
    Rs = np.empty((m, m))
    for a in range(m):
        ia = idx[a]
        nu[a] = z[ia] - x[ia]
        if ia >= 3 and ia <= 5:
            nu[a] = _wrap(nu[a])
        for b in range(m):
            Rs[a, b] = R[ia, idx[b]]
        if Rs[a, a] < 0.0:
            Rs[a, a] = -Rs[a, a]
        if Rs[a, a] < 1e-9:
            Rs[a, a] = 1e-9
    for a in range(m):
        for b in range(m):
            S[a, b] = P[idx[a], idx[b]] + Rs[a, b]
    Sinv, ok = _invert(S)
    if not ok:
        return 3, math.inf
    d2 = 0.0
    for a in range(m):
        s = 0.0
        for b in range(m):
            s += Sinv[a, b] * nu[b]
        d2 += nu[a] * s
    if not (d2 < threshold_sq):
        return 4, d2
    # K = P H^T S^-1  (15 x m)
    K = np.zeros((15, m))
    for i in range(15):
        for b in range(m):
            s = 0.0
            for a in range(m):
                s += P[i, idx[a]] * Sinv[a, b]
            K[i, b] = s
    for i in range(15):
        s = 0.0
        for a in range(m):
            s += K[i, a] * nu[a]
        x[i] += s
    # A = (I - K H) P = P - K P[idx, :]
    A = np.empty((15, 15))
    for i in range(15):
        for j in range(15):
            s = P[i, j]
            for a in range(m):
                s -= K[i, a] * P[idx[a], j]
            A[i, j] = s
    # P = A (I - K H)^T + K R K^T = A - A[:, idx] K^T + K R K^T
    KR = np.zeros((15, m))
    for i in range(15):
        for b in range(m):
            s = 0.0
            for a in range(m):
                s += K[i, a] * Rs[a, b]
            KR[i, b] = s
    for i in range(15):
        for j in range(15):
            s = A[i, j]
            for a in range(m):
                s += -A[i, idx[a]] * K[j, a] + KR[i, a] * K[j, a]
            P[i, j] = s
    wrap_angles_inplace(x)
    return 0, d2


@numba.njit(cache=True, nogil=True)
def covariance_status(C: np.ndarray) -> int:
    """0 when ``C`` (n x n) is finite, symmetric and positive semi-definite; else 1, 2 or 3 (which failed).

    Tolerances scale with ``max(1, max|C|)``: 1e-9 for symmetry, and PSD means a Cholesky
    factorisation of ``C + 1e-9 * scale * I`` succeeds.
    """
    n = C.shape[0]
    scale = 1.0
    for i in range(n):
        for j in range(n):
            v = C[i, j]
            if not math.isfinite(v):
                return 1
            if abs(v) > scale:
                scale = abs(v)
    tol = 1e-9 * scale
    for i in range(n):
        for j in range(i + 1, n):
            if abs(C[i, j] - C[j, i]) > tol:
                return 2
    L = np.zeros((n, n))
    for j in range(n):
        s = C[j, j] + tol
        for k in range(j):
            s -= L[j, k] * L[j, k]
        if s <= 0.0:
            return 3
        d = math.sqrt(s)
        L[j, j] = d
        for i in range(j + 1, n):
            t = C[i, j]
            for k in range(j):
                t -= L[i, k] * L[j, k]
            L[i, j] = t / d
    return 0
