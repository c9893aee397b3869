"""Worlds: a ROS map_server map (YAML + PGM/PNG) plus ArUco landmarks listed in the same YAML.

The YAML holds map_server's keys (``image``, ``resolution``, ``origin``,
``occupied_thresh``, ``free_thresh``, ``negate``, ``mode``) and two of ours::

    landmarks:                 # ArUco markers on walls, facing along ``yaw``
      - {id: 0, dictionary: DICT_4X4_50, size: 0.20, pose: [2.99, 0.0, 0.25, 3.14159]}
    start: [0.0, 0.0, 0.0]     # robot start pose (x, y, yaw) in map; default the origin

Grids are kept in ``nav_msgs/OccupancyGrid`` order: row 0 is the bottom of the
image (lowest y), column 0 the lowest x; cell ``(row, col)`` covers
``origin + (col, row) * resolution``.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = ["BUILTIN_WORLDS", "Landmark", "World", "WorldError", "builtin_world_path"]

#: Names accepted by :meth:`World.load` besides a path.
BUILTIN_WORLDS = ("box", "warehouse")

_WORLD_DIR = Path(__file__).parent / "worlds"


class WorldError(ValueError):
    """A world file that cannot be used: says which file, which key, what was expected and the fix."""


@dataclass(frozen=True, slots=True)
class Landmark:
    """An ArUco marker: ``size`` m black square centred at ``(x, y, z)``, its face looking along ``yaw``.

    ``yaw`` is the direction of the marker's outward normal in the map frame (the
    way a camera must look *against* to see it).
    """

    id: int
    dictionary: str
    size: float
    x: float
    y: float
    z: float
    yaw: float

    def corners(self) -> NDArray[np.float64]:
        """The four corners in the map frame, shape (4, 3), in ArUco order.

        ArUco order is top-left, top-right, bottom-right, bottom-left as seen by a
        viewer facing the marker.
        """
        return self.corners_with_margin(0.0)

    def corners_with_margin(self, margin: float) -> NDArray[np.float64]:
        """Corners of the square grown by ``margin`` m on every side, shape (4, 3)."""
        half = 0.5 * self.size + margin
        # A viewer facing the marker looks along -normal; their right is normal rotated by +90 deg.
        right = np.array([-math.sin(self.yaw), math.cos(self.yaw), 0.0])
        up = np.array([0.0, 0.0, 1.0])
        centre = np.array([self.x, self.y, self.z])
        return np.stack(
            [
                centre - half * right + half * up,
                centre + half * right + half * up,
                centre + half * right - half * up,
                centre - half * right - half * up,
            ]
        )


@dataclass(frozen=True, eq=False)
class World:
    """A loaded world: occupancy grid, map metadata, landmarks and the robot start pose.

    Attributes
    ----------
    occupancy : ndarray of int8, shape (height, width)
        0 free, 100 occupied, -1 unknown, OccupancyGrid row order (row 0 = lowest y).
    resolution : float
        Metres per cell.
    origin : tuple of float
        ``(x, y, yaw)`` of the lower-left cell's corner in the map frame (yaw must be 0).
    """

    name: str
    occupancy: NDArray[np.int8]
    resolution: float
    origin: tuple[float, float, float]
    landmarks: tuple[Landmark, ...] = ()
    start: tuple[float, float, float] = (0.0, 0.0, 0.0)
    path: str = ""
    occupied: NDArray[np.uint8] = field(init=False, repr=False)
    _clearance: NDArray[np.float32] | None = field(init=False, repr=False, default=None)

    def __post_init__(self) -> None:
        # What blocks rays and the robot: occupied cells (unknown counts as free space to drive).
        object.__setattr__(self, "occupied", np.ascontiguousarray(self.occupancy == 100, dtype=np.uint8))

    def __repr__(self) -> str:
        h, w = self.occupancy.shape
        return (
            f"<World {self.name} {w}x{h} cells at {self.resolution:g} m "
            f"({self.width_m:g} x {self.height_m:g} m) landmarks={len(self.landmarks)}>"
        )

    @property
    def clearance(self) -> NDArray[np.float32]:
        """:func:`~aiorobot.sim.clearance_map` of :attr:`occupied` (computed once): lets rays leap."""
        if self._clearance is None:
            from ._raycast import clearance_map

            object.__setattr__(self, "_clearance", clearance_map(self.occupied))
        assert self._clearance is not None
        return self._clearance

    @property
    def width_m(self) -> float:
        return self.occupancy.shape[1] * self.resolution

    @property
    def height_m(self) -> float:
        return self.occupancy.shape[0] * self.resolution

    def contains(self, x: float, y: float) -> bool:
        """Whether the map point ``(x, y)`` lies on the grid."""
        ox, oy, _ = self.origin
        return ox <= x < ox + self.width_m and oy <= y < oy + self.height_m

    def cell(self, x: float, y: float) -> tuple[int, int]:
        """``(row, col)`` of the map point ``(x, y)`` (may be outside the grid)."""
        ox, oy, _ = self.origin
        return math.floor((y - oy) / self.resolution), math.floor((x - ox) / self.resolution)

    def is_free_disc(self, x: float, y: float, radius: float) -> bool:
        """True when no occupied cell (nor the map edge) lies within ``radius`` of ``(x, y)``."""
        ox, oy, _ = self.origin
        res = self.resolution
        h, w = self.occupied.shape
        c0 = math.floor((x - radius - ox) / res)
        c1 = math.floor((x + radius - ox) / res)
        r0 = math.floor((y - radius - oy) / res)
        r1 = math.floor((y + radius - oy) / res)
        if c0 < 0 or r0 < 0 or c1 >= w or r1 >= h:
            return False
        # fast path: every point of the centre's cell is >= (clearance - sqrt 2) cells from any obstacle
        row, col = math.floor((y - oy) / res), math.floor((x - ox) / res)
        if (float(self.clearance[row, col]) - 1.4143) * res > radius:
            return True
        block = self.occupied[r0 : r1 + 1, c0 : c1 + 1]
        if not block.any():
            return True
        rows, cols = np.nonzero(block)
        # nearest point of each occupied cell to the centre
        cx0 = ox + (cols + c0) * res
        cy0 = oy + (rows + r0) * res
        dx = np.clip(x, cx0, cx0 + res) - x
        dy = np.clip(y, cy0, cy0 + res) - y
        return bool(np.all(dx * dx + dy * dy > radius * radius))

    def is_free_polygon(self, outline: NDArray[np.float64]) -> bool:
        """True when no occupied cell (nor the map edge) touches the polygon ``outline`` (M, 2), in map coordinates.

        A cell touches it when one of the polygon's edges crosses the cell's square or a corner of
        the square lies inside the polygon (a cell wholly inside it).
        """
        poly = np.asarray(outline, dtype=np.float64).reshape(-1, 2)
        ox, oy, _ = self.origin
        res = self.resolution
        h, w = self.occupied.shape
        c0, c1 = math.floor((poly[:, 0].min() - ox) / res), math.floor((poly[:, 0].max() - ox) / res)
        r0, r1 = math.floor((poly[:, 1].min() - oy) / res), math.floor((poly[:, 1].max() - oy) / res)
        if c0 < 0 or r0 < 0 or c1 >= w or r1 >= h:
            return False
        rows, cols = np.nonzero(self.occupied[r0 : r1 + 1, c0 : c1 + 1])
        if not len(rows):
            return True
        lo_x = (ox + (cols + c0) * res)[:, None]  # (K, 1) cell squares against (1, M) edges
        lo_y = (oy + (rows + r0) * res)[:, None]
        a, b = poly, np.roll(poly, -1, axis=0)
        dx, dy = (b[:, 0] - a[:, 0])[None, :], (b[:, 1] - a[:, 1])[None, :]
        # Liang-Barsky: the part of each edge a + t (b - a), t in [0, 1], inside each square
        t0, t1 = np.zeros((len(rows), len(poly))), np.ones((len(rows), len(poly)))
        for d, lo, start in ((dx, lo_x, a[None, :, 0]), (dy, lo_y, a[None, :, 1])):
            with np.errstate(divide="ignore", invalid="ignore"):
                ta, tb = (lo - start) / d, (lo + res - start) / d
            flat = d == 0.0
            outside = flat & ((start < lo) | (start > lo + res))
            t0 = np.where(flat, np.where(outside, np.inf, t0), np.maximum(t0, np.minimum(ta, tb)))
            t1 = np.where(flat, t1, np.minimum(t1, np.maximum(ta, tb)))
        if np.any(t0 <= t1):
            return False
        # no edge crosses an occupied square: one could still lie wholly inside the polygon
        corner_x, corner_y = lo_x[:, 0], lo_y[:, 0]
        inside = np.zeros(len(rows), dtype=bool)
        for i in range(len(poly)):
            (xi, yi), (xj, yj) = poly[i - 1], poly[i]
            crosses = (corner_y <= yi) != (corner_y <= yj)
            with np.errstate(divide="ignore", invalid="ignore"):
                x_at = xi + (corner_y - yi) * (xj - xi) / (yj - yi)
            inside ^= crosses & (x_at > corner_x)
        return not inside.any()

    def add_obstacle(self, x: float, y: float, half_x: float, half_y: float | None = None) -> None:
        """Put a box of half sizes ``half_x`` by ``half_y`` (m) centred at ``(x, y)`` into the world, not the map.

        What a person or a pushed box is: from now on it blocks the lidar's rays and the robot,
        while the map (``occupancy``, what the simulator publishes on ``/map``) stays as it was.
        """
        half_y = half_x if half_y is None else half_y
        ox, oy, _ = self.origin
        res = self.resolution
        h, w = self.occupied.shape
        c0, c1 = max(math.floor((x - half_x - ox) / res), 0), min(math.ceil((x + half_x - ox) / res), w)
        r0, r1 = max(math.floor((y - half_y - oy) / res), 0), min(math.ceil((y + half_y - oy) / res), h)
        if c0 >= c1 or r0 >= r1:
            raise ValueError(f"add_obstacle: the box at ({x:g}, {y:g}) of half sizes {half_x:g} x {half_y:g} m is outside {self!r}")
        self.occupied[r0:r1, c0:c1] = 1
        object.__setattr__(self, "_clearance", None)  # recomputed from the new grid at the next ray cast

    def to_image(self) -> NDArray[np.uint8]:
        """The grid as a map_server image (top row = highest y): free 254, occupied 0, unknown 205."""
        image = np.full(self.occupancy.shape, 205, dtype=np.uint8)
        image[self.occupancy == 0] = 254
        image[self.occupancy == 100] = 0
        return np.ascontiguousarray(image[::-1])

    def landmark(self, marker_id: int) -> Landmark:
        for lm in self.landmarks:
            if lm.id == marker_id:
                return lm
        raise KeyError(f"world {self.name!r} has no landmark with id {marker_id}")

    @classmethod
    def load(cls, world: str | os.PathLike[str]) -> World:
        """Load a built-in world by name (``"box"``, ``"warehouse"``) or a map YAML by path.

        Raises :class:`WorldError` naming the file, the key and the fix when anything is wrong.
        """
        from ._world_file import load_world

        text = os.fspath(world)
        if text in BUILTIN_WORLDS:
            return load_world(builtin_world_path(text), name=text)
        if not text.endswith((".yaml", ".yml")) and not os.path.exists(text):
            raise WorldError(
                f"world: expected a built-in name ({', '.join(BUILTIN_WORLDS)}) or a path to a map "
                f"YAML file, found {text!r}"
            )
        return load_world(Path(text))


def builtin_world_path(name: str) -> Path:
    """The YAML file of a built-in world."""
    if name not in BUILTIN_WORLDS:
        raise WorldError(f"world: expected one of {', '.join(BUILTIN_WORLDS)}, found {name!r}")
    return _WORLD_DIR / f"{name}.yaml"


def _landmark_dict(lm: Landmark) -> dict[str, Any]:
    return {"id": lm.id, "dictionary": lm.dictionary, "size": lm.size, "pose": [lm.x, lm.y, lm.z, lm.yaw]}
