"""Numba kernels for batch transforms. Imported lazily: importing numba costs ~0.3 s."""

from __future__ import annotations

import numba
import numpy as np
from numpy.typing import NDArray

__all__ = ["transform_points_kernel", "transform_points_numpy"]


@numba.njit(nogil=True, cache=True)
def _transform_points(
    points: NDArray[np.float64], R: NDArray[np.float64], t: NDArray[np.float64], out: NDArray[np.float64]
) -> None:  # pragma: no cover - compiled
    r00, r01, r02 = R[0, 0], R[0, 1], R[0, 2]
    r10, r11, r12 = R[1, 0], R[1, 1], R[1, 2]
    r20, r21, r22 = R[2, 0], R[2, 1], R[2, 2]
    tx, ty, tz = t[0], t[1], t[2]
    for i in range(points.shape[0]):
        x = points[i, 0]
        y = points[i, 1]
        z = points[i, 2]
        out[i, 0] = r00 * x + r01 * y + r02 * z + tx
        out[i, 1] = r10 * x + r11 * y + r12 * z + ty
        out[i, 2] = r20 * x + r21 * y + r22 * z + tz


def transform_points_kernel(
    points: NDArray[np.float64], R: NDArray[np.float64], t: NDArray[np.float64]
) -> NDArray[np.float64]:
    """``points @ R.T + t`` for (N, 3) float64 C-contiguous points, GIL released."""
    out = np.empty_like(points)
    _transform_points(points, R, t, out)
    return out


def transform_points_numpy(
    points: NDArray[np.float64], R: NDArray[np.float64], t: NDArray[np.float64]
) -> NDArray[np.float64]:
    """The same in plain numpy (the benchmark's reference)."""
    return points @ R.T + t
