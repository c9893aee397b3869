"""The Numba ray-casting kernel (imported lazily: numba costs ~0.3 s to import)."""

from __future__ import annotations

import math

import numpy as np
from numba import njit

__all__ = ["cast_rays", "cast_rays_skipping"]


@njit(cache=True, nogil=True)
def cast_rays(occupied, resolution, origin_x, origin_y, x, y, angles, max_range, out):  # pragma: no cover - compiled
    """Distance (m) along each world-frame angle to the first occupied cell, ``inf`` beyond ``max_range``.

    Amanatides-Woo grid traversal: exact distances to cell boundaries, no sampling step.
    A ray leaving the grid reads ``inf``; a ray starting inside an occupied cell reads 0.
    """
    h, w = occupied.shape
    px = (x - origin_x) / resolution
    py = (y - origin_y) / resolution
    limit = max_range / resolution
    i0 = int(math.floor(px))
    j0 = int(math.floor(py))
    for k in range(angles.shape[0]):
        dx = math.cos(angles[k])
        dy = math.sin(angles[k])
        i = i0
        j = j0
        if i < 0 or j < 0 or i >= w or j >= h:
            out[k] = np.inf
            continue
        if occupied[j, i]:
            out[k] = 0.0
            continue
        if dx > 0.0:
            step_i = 1
            t_max_x = (i + 1 - px) / dx
            t_delta_x = 1.0 / dx
        elif dx < 0.0:
            step_i = -1
            t_max_x = (px - i) / -dx
            t_delta_x = -1.0 / dx
        else:
            step_i = 0
            t_max_x = np.inf
            t_delta_x = np.inf
        if dy > 0.0:
            step_j = 1
            t_max_y = (j + 1 - py) / dy
            t_delta_y = 1.0 / dy
        elif dy < 0.0:
            step_j = -1
            t_max_y = (py - j) / -dy
            t_delta_y = -1.0 / dy
        else:
            step_j = 0
            t_max_y = np.inf
            t_delta_y = np.inf
        result = np.inf
        while True:
            if t_max_x < t_max_y:
                t = t_max_x
                i += step_i
                t_max_x += t_delta_x
            else:
                t = t_max_y
                j += step_j
                t_max_y += t_delta_y
            if t > limit or i < 0 or j < 0 or i >= w or j >= h:
                break
            if occupied[j, i]:
                result = t * resolution
                break
        out[k] = result
    return out


@njit(cache=True, nogil=True)
def cast_rays_skipping(occupied, clearance, resolution, origin_x, origin_y, x, y, angles, max_range, out):  # pragma: no cover
    """:func:`cast_rays` that leaps through open space using ``clearance``.

    ``clearance[j, i]`` is the distance (in cells) from cell ``(j, i)``'s centre to the
    nearest occupied cell's centre. Any point of that cell is then at least
    ``clearance - sqrt(2)`` cells from every occupied cell, so the ray may jump that far;
    near obstacles it walks cell by cell as :func:`cast_rays` does, so distances stay exact.
    """
    h, w = occupied.shape
    px0 = (x - origin_x) / resolution
    py0 = (y - origin_y) / resolution
    limit = max_range / resolution
    margin = 1.4143
    for k in range(angles.shape[0]):
        dx = math.cos(angles[k])
        dy = math.sin(angles[k])
        t = 0.0
        result = np.inf
        i = int(math.floor(px0))
        j = int(math.floor(py0))
        if i < 0 or j < 0 or i >= w or j >= h:
            out[k] = np.inf
            continue
        if occupied[j, i]:
            out[k] = 0.0
            continue
        while True:
            px = px0 + t * dx
            py = py0 + t * dy
            i = int(math.floor(px))
            j = int(math.floor(py))
            if i < 0 or j < 0 or i >= w or j >= h:
                break
            leap = clearance[j, i] - margin
            if leap > 2.0:
                t += leap
                if t > limit:
                    break
                continue
            # walk cells exactly (Amanatides-Woo) from here for a few cells
            if dx > 0.0:
                step_i = 1
                t_max_x = t + (i + 1 - px) / dx
                t_delta_x = 1.0 / dx
            elif dx < 0.0:
                step_i = -1
                t_max_x = t + (px - i) / -dx
                t_delta_x = -1.0 / dx
            else:
                step_i = 0
                t_max_x = np.inf
                t_delta_x = np.inf
            if dy > 0.0:
                step_j = 1
                t_max_y = t + (j + 1 - py) / dy
                t_delta_y = 1.0 / dy
            elif dy < 0.0:
                step_j = -1
                t_max_y = t + (py - j) / -dy
                t_delta_y = -1.0 / dy
            else:
                step_j = 0
                t_max_y = np.inf
                t_delta_y = np.inf
            done = False
            for _ in range(4):
                if t_max_x < t_max_y:
                    t = t_max_x
                    i += step_i
                    t_max_x += t_delta_x
                else:
                    t = t_max_y
                    j += step_j
                    t_max_y += t_delta_y
                if t > limit or i < 0 or j < 0 or i >= w or j >= h:
                    done = True
                    break
                if occupied[j, i]:
                    result = t * resolution
                    done = True
                    break
            if done:
                break
            # resume just inside the current cell (t is on its entry boundary)
            t += 1e-9
        out[k] = result
    return out
