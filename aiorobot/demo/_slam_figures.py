"""How well a map built by SLAM agrees with the simulator's world: the demo's and the tests' yardstick."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = ["MapAgreement", "map_agreement"]


@dataclass(frozen=True, slots=True)
class MapAgreement:
    """``precision``: share of the built map's occupied cells within ``tolerance_m`` of a true wall;
    ``recall``: share of the wall cells the route's scans reached that the built map marks occupied
    (within one cell: a beam ends on the face between a wall cell and the free one before it)."""

    precision: float
    recall: float
    occupied_cells: int
    seen_wall_cells: int
    tolerance_m: float


def map_agreement(grid: Any, world: Any, route_xy: NDArray[np.float64], *, tolerance_m: float = 0.1,
                  beams: int = 360, range_max: float = 12.0) -> MapAgreement:
    """Compare ``grid`` (an :class:`~aiorobot.nav.OccupancyMap` in the world's frame) with ``world``
    (an :class:`~aiorobot.sim.World`); ``route_xy`` (N, 2): where the robot's lidar looked from."""
    from aiorobot.sim._raycast import raycast

    data, res = np.asarray(grid.data), float(grid.resolution)
    ox, oy = float(grid.origin[0]), float(grid.origin[1])
    wres, (wox, woy) = float(world.resolution), world.origin[:2]
    wh, ww = world.occupied.shape
    rows, cols = np.nonzero(data == 100)
    cx, cy = ox + (cols + 0.5) * res, oy + (rows + 0.5) * res
    wr = np.floor((cy - woy) / wres).astype(np.int64)
    wc = np.floor((cx - wox) / wres).astype(np.int64)
    inside = (wr >= 0) & (wc >= 0) & (wr < wh) & (wc < ww)
    near = np.zeros(len(rows), dtype=bool)
    # clearance: cells from each cell centre to the nearest occupied cell centre
    near[inside] = world.clearance[wr[inside], wc[inside]] * wres <= tolerance_m
    angles = -np.pi + 2.0 * np.pi * np.arange(beams) / beams
    seen: set[tuple[int, int]] = set()
    for x, y in np.asarray(route_xy, dtype=np.float64).reshape(-1, 2):
        r = raycast(world.occupied, wres, (wox, woy), (x, y), angles, range_max, clearance=world.clearance)
        ok = np.isfinite(r)
        hx = x + (r[ok] + 0.5 * wres) * np.cos(angles[ok])  # half a cell past the face: inside the wall cell
        hy = y + (r[ok] + 0.5 * wres) * np.sin(angles[ok])
        hr = np.floor((hy - woy) / wres).astype(np.int64)
        hc = np.floor((hx - wox) / wres).astype(np.int64)
        seen.update(zip(hr.tolist(), hc.tolist()))
    cells = np.array(sorted(seen), dtype=np.int64).reshape(-1, 2)
    cells = cells[(cells[:, 0] >= 0) & (cells[:, 1] >= 0) & (cells[:, 0] < wh) & (cells[:, 1] < ww)]
    cells = cells[world.occupied[cells[:, 0], cells[:, 1]] == 1]
    occupied = np.pad(data == 100, 1)  # a one-cell border of False: the 3 x 3 window never leaves the grid
    br = np.floor((woy + (cells[:, 0] + 0.5) * wres - oy) / res).astype(np.int64) + 1
    bc = np.floor((wox + (cells[:, 1] + 0.5) * wres - ox) / res).astype(np.int64) + 1
    ok = (br >= 1) & (bc >= 1) & (br <= data.shape[0]) & (bc <= data.shape[1])
    marked = np.zeros(len(cells), dtype=bool)
    for dr in (-1, 0, 1):
        for dc in (-1, 0, 1):
            marked[ok] |= occupied[br[ok] + dr, bc[ok] + dc]
    return MapAgreement(float(near.mean()) if len(near) else 0.0, float(marked.mean()) if len(marked) else 0.0,
                        int(len(rows)), int(len(cells)), tolerance_m)
