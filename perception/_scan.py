"""LaserScan -> points (vectorised), breakpoint segmentation and obstacle extraction (Numba, nogil)."""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from ._images import BadInput

__all__ = ["extract_obstacles", "scan_to_points", "segment_scan", "warm_up"]


def scan_to_points(msg: Any) -> NDArray[np.float64]:
    """Points (N, 2) in the scan's frame for the beams with a finite range inside [range_min, range_max].

    NaN and inf ranges are skipped (no return). Raises :class:`BadInput` when the
    beam count disagrees with the angles or with ``intensities``.
    """
    ranges = np.asarray(msg.ranges, dtype=np.float64)
    increment = float(msg.angle_increment)
    if ranges.size == 0:
        raise BadInput("empty scan: no ranges")
    if not (np.isfinite(msg.angle_min) and np.isfinite(increment) and increment != 0.0):
        raise BadInput(f"scan angles must be finite with a non-zero increment, got angle_min={msg.angle_min}, "
                       f"angle_increment={increment}")
    expected = int(round((float(msg.angle_max) - float(msg.angle_min)) / increment)) + 1
    if abs(expected - ranges.size) > 1:
        raise BadInput(f"scan has {ranges.size} ranges but angle_min..angle_max/angle_increment gives {expected}")
    intensities = np.asarray(msg.intensities)
    if intensities.size not in (0, ranges.size):
        raise BadInput(f"scan has {ranges.size} ranges but {intensities.size} intensities")
    angles = float(msg.angle_min) + increment * np.arange(ranges.size)
    with np.errstate(invalid="ignore"):
        valid = np.isfinite(ranges) & (ranges >= msg.range_min) & (ranges <= msg.range_max)
    r = ranges[valid]
    return np.column_stack((r * np.cos(angles[valid]), r * np.sin(angles[valid])))


_kernels: dict[str, Any] = {}


def _segment_kernel() -> Any:
    kernel = _kernels.get("segment")
    if kernel is None:
        import numba

        @numba.njit(nogil=True, cache=True)
        def segment(points: Any, threshold: float, min_points: int) -> Any:  # pragma: no cover - compiled
            n = points.shape[0]
            labels = np.full(n, -1, np.int64)
            if n == 0:
                return labels
            start = 0
            label = 0
            for i in range(1, n + 1):
                gap = True
                if i < n:
                    dx = points[i, 0] - points[i - 1, 0]
                    dy = points[i, 1] - points[i - 1, 1]
                    gap = dx * dx + dy * dy > threshold * threshold
                if gap:
                    if i - start >= min_points:
                        for j in range(start, i):
                            labels[j] = label
                        label += 1
                    start = i
            return labels

        kernel = _kernels["segment"] = segment
    return kernel


def segment_scan(points: NDArray[np.float64], break_distance: float = 0.2, min_points: int = 3) -> NDArray[np.int64]:
    """Breakpoint segmentation of consecutive scan points: a label per point, -1 for too-small segments.

    A new segment starts wherever two consecutive points are more than
    ``break_distance`` metres apart. Runs in Numba with the GIL released.
    """
    pts = np.ascontiguousarray(points, dtype=np.float64)
    if pts.ndim != 2 or pts.shape[1] != 2:
        raise ValueError(f"points must be (N, 2), got shape {pts.shape}")
    return _segment_kernel()(pts, float(break_distance), int(min_points))


def _obstacle_kernel() -> Any:
    kernel = _kernels.get("obstacles")
    if kernel is None:
        import numba

        @numba.njit(nogil=True, cache=True)
        def obstacles(points: Any, labels: Any, count: int) -> Any:  # pragma: no cover - compiled
            out = np.zeros((count, 4))  # cx, cy, radius, n
            for i in range(points.shape[0]):
                k = labels[i]
                if k >= 0:
                    out[k, 0] += points[i, 0]
                    out[k, 1] += points[i, 1]
                    out[k, 3] += 1.0
            for k in range(count):
                out[k, 0] /= out[k, 3]
                out[k, 1] /= out[k, 3]
            for i in range(points.shape[0]):
                k = labels[i]
                if k >= 0:
                    d = np.sqrt((points[i, 0] - out[k, 0]) ** 2 + (points[i, 1] - out[k, 1]) ** 2)
                    if d > out[k, 2]:
                        out[k, 2] = d
            return out

        kernel = _kernels["obstacles"] = obstacles
    return kernel


def extract_obstacles(points: NDArray[np.float64], labels: NDArray[np.int64]) -> NDArray[np.float64]:
    """One row per segment: ``(centre x, centre y, radius, point count)``, shape (K, 4)."""
    labels = np.ascontiguousarray(labels, dtype=np.int64)
    count = int(labels.max()) + 1 if labels.size else 0
    return _obstacle_kernel()(np.ascontiguousarray(points, dtype=np.float64), labels, count)


def warm_up() -> None:
    """Compile (first run) or load both kernels with the argument types the functions above pass."""
    points = np.array([[1.0, 0.0], [1.0, 0.05], [1.0, 0.1]])
    extract_obstacles(points, segment_scan(points, 0.2, 3))
