"""Numba kernels of the collision monitor: points inside a zone, and time to collision.

A zone is a polygon ``vertices`` (M, 2) or, when M is 0, a circle of ``radius`` about the
origin, both in the robot's base frame. The point-in-polygon test is Nav2's
(``Polygon::isPointInside``: a +x ray from the point, crossing parity; an edge parallel to the
ray never counts); the circle's is Nav2's ``Circle``: ``x**2 + y**2 < radius**2``.
"""

from __future__ import annotations

import math

import numba
import numpy as np

__all__ = ["collision_time", "inside_mask", "warm_up"]


@numba.njit(cache=True, nogil=True, inline="always")
def _inside(x, y, vertices, radius_sq):  # pragma: no cover - compiled
    m = vertices.shape[0]
    if m == 0:
        return x * x + y * y < radius_sq
    res = False
    i = m - 1
    for j in range(m):
        yi = vertices[i, 1]
        yj = vertices[j, 1]
        if (y <= yi) == (y > yj):
            x_inter = vertices[i, 0] + (y - yi) * (vertices[j, 0] - vertices[i, 0]) / (yj - yi)
            if x_inter > x:
                res = not res
        i = j
    return res


@numba.njit(cache=True, nogil=True)
def inside_mask(points, vertices, radius):  # pragma: no cover - compiled
    """(N,) bool: which of ``points`` (N, 2) lie inside the zone."""
    n = points.shape[0]
    out = np.zeros(n, dtype=np.bool_)
    r2 = radius * radius
    for k in range(n):
        out[k] = _inside(points[k, 0], points[k, 1], vertices, r2)
    return out


@numba.njit(cache=True, nogil=True)
def _count_moved(points, vertices, r2, px, py, pth):  # pragma: no cover - compiled
    """How many points fall inside the zone carried to pose (px, py, pth) of the base frame."""
    c = math.cos(pth)
    s = math.sin(pth)
    count = 0
    for k in range(points.shape[0]):
        dx = points[k, 0] - px
        dy = points[k, 1] - py
        if _inside(dx * c + dy * s, -dx * s + dy * c, vertices, r2):
            count += 1
    return count


@numba.njit(cache=True, nogil=True)
def collision_time(points, vertices, radius, min_points, vx, vy, wz, time_before_collision, time_step):  # pragma: no cover
    """Nav2's ``Polygon::getCollisionTime``: seconds until ``min_points`` of ``points`` fall in the zone.

    The base moves with the body twist (vx, vy, wz), the velocity vector turning with it
    (``projectState``), in steps of ``time_step`` up to ``time_before_collision``; 0.0 when the
    zone already holds them, -1.0 when no collision comes within the horizon.
    """
    r2 = radius * radius
    if _count_moved(points, vertices, r2, 0.0, 0.0, 0.0) >= min_points:
        return 0.0
    px = 0.0
    py = 0.0
    pth = 0.0
    t = 0.0
    while t <= time_before_collision:
        dth = wz * time_step
        px += vx * time_step
        py += vy * time_step
        pth += dth
        c = math.cos(dth)
        s = math.sin(dth)
        nvx = vx * c - vy * s
        vy = vx * s + vy * c
        vx = nvx
        if _count_moved(points, vertices, r2, px, py, pth) >= min_points:
            return t
        t += time_step
    return -1.0


def warm_up() -> None:
    """Compile (first run) or load the kernels with the argument types the monitor passes."""
    pts = np.zeros((2, 2))
    square = np.array([[0.5, 0.5], [0.5, -0.5], [-0.5, -0.5], [-0.5, 0.5]])
    inside_mask(pts, square, 0.0)
    inside_mask(pts, np.zeros((0, 2)), 0.5)
    collision_time(pts, square, 0.0, 1, 0.1, 0.0, 0.0, 1.0, 0.1)
