"""Ray casting on an occupancy grid: the geometry behind the simulated lidar and occlusion tests."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["clearance_map", "raycast"]


def clearance_map(occupied: ArrayLike) -> NDArray[np.float32]:
    """Distance (cells) from every cell centre to the nearest occupied cell centre, float32.

    Cells outside the grid count as free. A grid without obstacles gets a large constant.
    """
    import cv2

    grid = np.asarray(occupied) != 0
    if not grid.any():
        return np.full(grid.shape, float(sum(grid.shape)), dtype=np.float32)
    free = np.ascontiguousarray(~grid, dtype=np.uint8)
    return cv2.distanceTransform(free, cv2.DIST_L2, cv2.DIST_MASK_PRECISE)


def raycast(
    occupied: ArrayLike,
    resolution: float,
    origin: tuple[float, float],
    position: tuple[float, float],
    angles: ArrayLike,
    max_range: float = math.inf,
    *,
    out: NDArray[np.float64] | None = None,
    clearance: NDArray[np.float32] | None = None,
) -> NDArray[np.float64]:
    """Distances from ``position`` to the first occupied cell along each of ``angles``.

    Parameters
    ----------
    occupied : array_like, shape (height, width)
        Non-zero where a cell blocks rays; OccupancyGrid row order (row 0 = lowest y).
    resolution : float
        Metres per cell, > 0.
    origin : (float, float)
        Map coordinates of the lower-left corner of cell ``(0, 0)``.
    position : (float, float)
        Ray origin in map coordinates (m).
    angles : array_like, shape (n,)
        Ray directions in the map frame (rad, counter-clockwise from +x).
    max_range : float
        Rays travelling further read ``inf``; so do rays that leave the grid.
    out : ndarray, shape (n,), optional
        Where to write the result.
    clearance : ndarray of float32, shape (height, width), optional
        :func:`clearance_map` of ``occupied``: rays then leap through open space
        (same results, several times faster on large maps).

    Returns
    -------
    ndarray of float64, shape (n,)
        Exact distances (m) to the first occupied cell boundary, ``inf`` for no hit,
        0 when ``position`` lies in an occupied cell.

    The kernel is compiled by Numba and releases the GIL, so it may run in a thread.
    """
    from ._raycast_kernel import cast_rays, cast_rays_skipping

    grid = np.asarray(occupied)
    if grid.ndim != 2:
        raise ValueError(f"occupied must have shape (height, width), got shape {grid.shape}")
    if grid.dtype != np.uint8:
        grid = (grid != 0).astype(np.uint8)
    grid = np.ascontiguousarray(grid)
    if not resolution > 0:
        raise ValueError(f"resolution must be > 0 m, got {resolution!r}")
    dirs = np.ascontiguousarray(angles, dtype=np.float64)
    if dirs.ndim != 1:
        raise ValueError(f"angles must have shape (n,), got shape {dirs.shape}")
    if out is None:
        out = np.empty(dirs.shape[0], dtype=np.float64)
    elif out.shape != dirs.shape or out.dtype != np.float64:
        raise ValueError(f"out must be float64 of shape {dirs.shape}, got {out.dtype} {out.shape}")
    if clearance is not None:
        if clearance.shape != grid.shape or clearance.dtype != np.float32:
            raise ValueError(f"clearance must be float32 of shape {grid.shape}, got {clearance.dtype} {clearance.shape}")
        return cast_rays_skipping(
            grid, clearance, float(resolution), float(origin[0]), float(origin[1]),
            float(position[0]), float(position[1]), dirs, float(max_range), out,
        )
    return cast_rays(
        grid, float(resolution), float(origin[0]), float(origin[1]),
        float(position[0]), float(position[1]), dirs, float(max_range), out,
    )
