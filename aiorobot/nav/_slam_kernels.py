"""Numba kernels of the SLAM scan matcher (cached, GIL released).

Olson's real-time correlative scan matching ("Real-Time Correlative Scan Matching", ICRA 2009):
reference points are smeared into a likelihood grid (a Gaussian of each point, the max where
they overlap); a scan's score at a pose is the mean grid value under its points. The search is
exhaustive over a window of translations (whole cells) and rotations, made fast by branch and
bound on two resolutions: a coarse grid whose cell holds the max of the ``block`` x ``block``
fine cells it covers bounds the fine score of every translation in that block, so blocks are
refined best first and the search stops once no block's bound beats the best fine score.
:func:`refine` then polishes the best pose below a cell with Gauss-Newton on the bilinearly
interpolated grid (as Cartographer's Ceres matcher does) and returns the normal matrix, from
which the caller takes the match's covariance.

Grids are (H, W) float32 in OccupancyGrid order: cell (row, col) covers
``origin + (col, row) * resolution``.
"""

from __future__ import annotations

import math

import numba
import numpy as np

__all__ = ["block_max", "refine", "score", "search", "splat", "warm_up"]


@numba.njit(cache=True, nogil=True)
def splat(grid, points, origin_x, origin_y, resolution, sigma):  # pragma: no cover - compiled
    """Smear each point (N, 2) into ``grid`` as exp(-d^2 / 2 sigma^2), keeping the max per cell.

    The Gaussian is separable: per point, one factor per column and one per row of its window
    (2 (2 reach + 1) exponentials instead of (2 reach + 1)^2).
    """
    h, w = grid.shape
    reach = int(math.ceil(2.5 * sigma / resolution))
    inv2s2 = 1.0 / (2.0 * sigma * sigma)
    fx = np.empty(2 * reach + 1)
    fy = np.empty(2 * reach + 1)
    for k in range(points.shape[0]):
        u = (points[k, 0] - origin_x) / resolution - 0.5
        v = (points[k, 1] - origin_y) / resolution - 0.5
        if not (math.isfinite(u) and math.isfinite(v)):
            continue
        cu = int(round(u))
        cv = int(round(v))
        if cu < -reach or cv < -reach or cu >= w + reach or cv >= h + reach:
            continue
        for d in range(2 * reach + 1):
            dx = (cu - reach + d - u) * resolution
            dy = (cv - reach + d - v) * resolution
            fx[d] = math.exp(-dx * dx * inv2s2)
            fy[d] = math.exp(-dy * dy * inv2s2)
        for r in range(max(0, cv - reach), min(h, cv + reach + 1)):
            gy = fy[r - cv + reach]
            for c in range(max(0, cu - reach), min(w, cu + reach + 1)):
                val = gy * fx[c - cu + reach]
                if val > grid[r, c]:
                    grid[r, c] = val


@numba.njit(cache=True, nogil=True)
def block_max(fine, block):  # pragma: no cover - compiled
    """out[r, c] = max of fine[r:r+block, c:c+block] (clipped at the edges): the coarse level's bound.

    Row-major passes over contiguous memory (a max over ``block`` shifted copies per axis).
    """
    h, w = fine.shape
    rows = fine.copy()
    for r in range(h):
        for k in range(1, block):
            for c in range(w - k):
                v = fine[r, c + k]
                if v > rows[r, c]:
                    rows[r, c] = v
    out = rows.copy()
    for r in range(h):
        for k in range(1, min(block, h - r)):
            for c in range(w):
                v = rows[r + k, c]
                if v > out[r, c]:
                    out[r, c] = v
    return out


@numba.njit(cache=True, nogil=True, inline="always")
def _sum_at(grid, qi, qj, di, dj):  # pragma: no cover - compiled
    h, w = grid.shape
    s = 0.0
    for k in range(qi.shape[0]):
        r = qi[k] + di
        c = qj[k] + dj
        if 0 <= r < h and 0 <= c < w:
            s += grid[r, c]
    return s


@numba.njit(cache=True, nogil=True)
def search(fine, coarse, block, points, x0, y0, thetas, half_cells, origin_x, origin_y, resolution,
           exclude_x, exclude_y, exclude_radius):  # pragma: no cover - compiled
    """Best pose of the scan ``points`` (N, 2, robot frame) over translations of up to ``half_cells``
    cells around (x0, y0) and the rotations ``thetas`` (absolute yaw, rad).

    Translations within ``exclude_radius`` m of (exclude_x, exclude_y) are skipped (a negative
    radius skips none): the second search of the ambiguity test. Returns (x, y, theta, score)
    with score the mean fine value under the points; score -1 when nothing was searched.
    """
    n = points.shape[0]
    na = thetas.shape[0]
    qi = np.empty((na, n), dtype=np.int64)
    qj = np.empty((na, n), dtype=np.int64)
    for a in range(na):
        c = math.cos(thetas[a])
        s = math.sin(thetas[a])
        for k in range(n):
            px = points[k, 0]
            py = points[k, 1]
            qj[a, k] = int(math.floor((x0 + c * px - s * py - origin_x) / resolution))
            qi[a, k] = int(math.floor((y0 + s * px + c * py - origin_y) / resolution))
    nb = (2 * half_cells) // block + 1
    cand_score = np.empty(na * nb * nb)
    cand_a = np.empty(na * nb * nb, dtype=np.int64)
    cand_di = np.empty(na * nb * nb, dtype=np.int64)
    cand_dj = np.empty(na * nb * nb, dtype=np.int64)
    m = 0
    for a in range(na):
        for bi in range(nb):
            di0 = -half_cells + bi * block
            for bj in range(nb):
                dj0 = -half_cells + bj * block
                cand_score[m] = _sum_at(coarse, qi[a], qj[a], di0, dj0)
                cand_a[m] = a
                cand_di[m] = di0
                cand_dj[m] = dj0
                m += 1
    order = np.argsort(-cand_score)
    best = -1.0
    best_a = 0
    best_di = 0
    best_dj = 0
    ex2 = exclude_radius * exclude_radius
    for o in range(m):
        k = order[o]
        if cand_score[k] <= best:
            break
        a = cand_a[k]
        for di in range(cand_di[k], min(cand_di[k] + block, half_cells + 1)):
            for dj in range(cand_dj[k], min(cand_dj[k] + block, half_cells + 1)):
                if exclude_radius >= 0.0:
                    ex = x0 + dj * resolution - exclude_x
                    ey = y0 + di * resolution - exclude_y
                    if ex * ex + ey * ey < ex2:
                        continue
                s = _sum_at(fine, qi[a], qj[a], di, dj)
                if s > best:
                    best = s
                    best_a = a
                    best_di = di
                    best_dj = dj
    if best < 0.0:
        return x0, y0, thetas[0] if na > 0 else 0.0, -1.0
    return x0 + best_dj * resolution, y0 + best_di * resolution, thetas[best_a], best / max(n, 1)


@numba.njit(cache=True, nogil=True, inline="always")
def _bilinear(grid, u, v):  # pragma: no cover - compiled
    """Value and d/du, d/dv of the grid interpolated at cell-centre coordinates (u, v)."""
    h, w = grid.shape
    j0 = int(math.floor(u))
    i0 = int(math.floor(v))
    fu = u - j0
    fv = v - i0
    if i0 < 0 or j0 < 0 or i0 + 1 >= h or j0 + 1 >= w:
        return 0.0, 0.0, 0.0
    a = grid[i0, j0]
    b = grid[i0, j0 + 1]
    c = grid[i0 + 1, j0]
    d = grid[i0 + 1, j0 + 1]
    val = (a * (1 - fu) + b * fu) * (1 - fv) + (c * (1 - fu) + d * fu) * fv
    du = (b - a) * (1 - fv) + (d - c) * fv
    dv = (c - a) * (1 - fu) + (d - b) * fu
    return val, du, dv


@numba.njit(cache=True, nogil=True)
def score(grid, points, x, y, theta, origin_x, origin_y, resolution):  # pragma: no cover - compiled
    """Mean interpolated grid value under the points (N, 2, robot frame) placed at (x, y, theta)."""
    c = math.cos(theta)
    s = math.sin(theta)
    total = 0.0
    for k in range(points.shape[0]):
        px = points[k, 0]
        py = points[k, 1]
        u = (x + c * px - s * py - origin_x) / resolution - 0.5
        v = (y + s * px + c * py - origin_y) / resolution - 0.5
        total += _bilinear(grid, u, v)[0]
    return total / max(points.shape[0], 1)


@numba.njit(cache=True, nogil=True)
def refine(grid, points, x, y, theta, origin_x, origin_y, resolution, max_shift, max_turn, iterations):  # pragma: no cover
    """Gauss-Newton (Levenberg damped) on sum (1 - f)^2 from (x, y, theta), staying within
    ``max_shift`` m / ``max_turn`` rad of it. Returns (x, y, theta, mean f, normal matrix
    J^T J (3, 3), sum of squared residuals), all at the returned pose."""
    n = points.shape[0]
    sx, sy, st = x, y, theta
    cx, cy, ct = x, y, theta
    lam = 1e-3
    jtj = np.zeros((3, 3))
    best_jtj = np.zeros((3, 3))
    jtr = np.zeros(3)
    best_jtr = np.zeros(3)
    best_sse = np.inf
    for _ in range(iterations + 1):
        c = math.cos(ct)
        s = math.sin(ct)
        jtj[:, :] = 0.0
        jtr[:] = 0.0
        sse = 0.0
        for k in range(n):
            px = points[k, 0]
            py = points[k, 1]
            u = (cx + c * px - s * py - origin_x) / resolution - 0.5
            v = (cy + s * px + c * py - origin_y) / resolution - 0.5
            val, du, dv = _bilinear(grid, u, v)
            r = 1.0 - val
            gx = du / resolution
            gy = dv / resolution
            j0 = -gx
            j1 = -gy
            j2 = -(gx * (-s * px - c * py) + gy * (c * px - s * py))
            jtj[0, 0] += j0 * j0
            jtj[0, 1] += j0 * j1
            jtj[0, 2] += j0 * j2
            jtj[1, 1] += j1 * j1
            jtj[1, 2] += j1 * j2
            jtj[2, 2] += j2 * j2
            jtr[0] += j0 * r
            jtr[1] += j1 * r
            jtr[2] += j2 * r
            sse += r * r
        jtj[1, 0] = jtj[0, 1]
        jtj[2, 0] = jtj[0, 2]
        jtj[2, 1] = jtj[1, 2]
        if sse < best_sse:  # accept the step (the first evaluation is the start)
            best_sse = sse
            x, y, theta = cx, cy, ct
            best_jtj[:, :] = jtj
            best_jtr[:] = jtr
            lam *= 0.3
        else:  # reject: back to the best pose, damp harder
            lam *= 10.0
        a = best_jtj.copy()
        for d in range(3):
            a[d, d] += lam * a[d, d] + 1e-9
        step = np.linalg.solve(a, -best_jtr)
        cx = min(max(x + step[0], sx - max_shift), sx + max_shift)
        cy = min(max(y + step[1], sy - max_shift), sy + max_shift)
        ct = min(max(theta + step[2], st - max_turn), st + max_turn)
        if not math.isfinite(cx + cy + ct):
            break
    mean = 0.0
    if n > 0:
        mean = score(grid, points, x, y, theta, origin_x, origin_y, resolution)
    return x, y, theta, mean, best_jtj, best_sse


def warm_up() -> None:
    """Compile (first run) or load the kernels on tiny inputs of the types the matcher passes."""
    grid = np.zeros((8, 8), dtype=np.float32)
    pts = np.zeros((2, 2))
    splat(grid, pts, 0.0, 0.0, 0.05, 0.1)
    coarse = block_max(grid, 2)
    search(grid, coarse, 2, pts, 0.1, 0.1, np.zeros(2), 2, 0.0, 0.0, 0.05, 0.0, 0.0, -1.0)
    score(grid, pts, 0.1, 0.1, 0.0, 0.0, 0.0, 0.05)
    refine(grid, pts, 0.1, 0.1, 0.0, 0.0, 0.0, 0.05, 0.1, 0.1, 2)
