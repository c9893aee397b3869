"""Robot footprints as nav2_costmap_2d defines them, and the footprint collision check.

Parameters as Nav2's costmap: ``footprint`` (a polygon, ``"[[x, y], ...]"`` in the base frame;
``"[]"`` for none) or else ``robot_radius``; ``footprint_padding`` moves each polygon vertex
outwards along x and y (``padFootprint``). A round robot's outline is Nav2's 16-gon
(``makeFootprintFromRadius``). The inscribed radius (nearest edge or vertex) is the costmap's
inflation ``inscribed_radius``; the circumscribed radius is the farthest vertex
(``calculateMinAndMaxDistances``).

The cost of a footprint at a pose is Nav2's ``FootprintCollisionChecker::footprintCost``: the
highest cell cost along its outline (each edge rasterised with Bresenham's line), LETHAL when a
vertex is off the map.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numba
import numpy as np
from numpy.typing import NDArray

__all__ = ["Footprint", "footprint_cost"]


def _distance_to_segment(ax: float, ay: float, bx: float, by: float) -> float:
    """Distance from the origin to the segment a-b."""
    ex, ey = bx - ax, by - ay
    length2 = ex * ex + ey * ey
    t = 0.0 if length2 == 0.0 else min(max(-(ax * ex + ay * ey) / length2, 0.0), 1.0)
    return float(np.hypot(ax + t * ex, ay + t * ey))


@dataclass(frozen=True)
class Footprint:
    """A footprint: ``vertices`` (M, 2) in the base frame; ``radius`` set when it is round."""

    vertices: NDArray[np.float64]
    radius: float | None = None

    def __post_init__(self) -> None:
        v = np.ascontiguousarray(self.vertices, dtype=np.float64).reshape(-1, 2)
        if len(v) < 3 or not np.isfinite(v).all():
            raise ValueError(f"footprint: expected 3 or more finite [x, y] points, found {v.tolist()}")
        object.__setattr__(self, "vertices", v)

    @classmethod
    def circle(cls, radius: float) -> Footprint:
        if not radius > 0:
            raise ValueError(f"robot_radius: expected > 0, found {radius}")
        a = np.arange(16) * (2.0 * np.pi / 16)
        return cls(np.column_stack([radius * np.cos(a), radius * np.sin(a)]), float(radius))

    @classmethod
    def from_parameters(cls, footprint: Any = "[]", robot_radius: float = 0.22, footprint_padding: float = 0.01) -> Footprint:
        """Nav2's costmap parameters: a ``footprint`` polygon (string or flat list) wins over ``robot_radius``."""
        from ._collision_monitor import parse_points

        empty = footprint is None or (isinstance(footprint, str) and footprint.strip() in ("", "[]")) or \
            (not isinstance(footprint, str) and len(footprint) == 0)
        if empty:
            return cls.circle(float(robot_radius))
        v = parse_points(footprint, "parameter footprint")
        return cls(v + np.sign(v) * float(footprint_padding))

    @property
    def is_circular(self) -> bool:
        return self.radius is not None

    @property
    def inscribed_radius(self) -> float:
        if self.radius is not None:
            return self.radius
        v = self.vertices
        return min(min(float(np.hypot(*p)) for p in v),
                   min(_distance_to_segment(*v[i], *v[(i + 1) % len(v)]) for i in range(len(v))))

    @property
    def circumscribed_radius(self) -> float:
        return self.radius if self.radius is not None else float(np.hypot(self.vertices[:, 0], self.vertices[:, 1]).max())

    def at(self, x: float, y: float, yaw: float) -> NDArray[np.float64]:
        """The outline (M, 2) with the base at pose (x, y, yaw)."""
        c, s = np.cos(yaw), np.sin(yaw)
        v = self.vertices
        return np.column_stack([x + c * v[:, 0] - s * v[:, 1], y + s * v[:, 0] + c * v[:, 1]])

    def to_string(self) -> str:
        """Nav2's string form ``[[x, y], ...]``."""
        return "[" + ", ".join(f"[{x:g}, {y:g}]" for x, y in self.vertices) + "]"


@numba.njit(cache=True, nogil=True)
def _line_cost(cost, c0, r0, c1, r1):  # pragma: no cover - compiled
    """Highest cost on Bresenham's line between two cells (Nav2's lineCost); stops at LETHAL."""
    dc = abs(c1 - c0)
    dr = abs(r1 - r0)
    sc = 1 if c1 > c0 else -1
    sr = 1 if r1 > r0 else -1
    err = dc - dr
    best = 0
    while True:
        v = cost[r0, c0]
        if v == 254:
            return 254
        if v > best:
            best = v
        if c0 == c1 and r0 == r1:
            return best
        e2 = 2 * err
        if e2 > -dr:
            err -= dr
            c0 += sc
        if e2 < dc:
            err += dc
            r0 += sr


@numba.njit(cache=True, nogil=True)
def _outline_cost(cost, outline, origin_x, origin_y, resolution):  # pragma: no cover - compiled
    h, w = cost.shape
    m = outline.shape[0]
    cols = np.empty(m, dtype=np.int64)
    rows = np.empty(m, dtype=np.int64)
    for i in range(m):
        fc = (outline[i, 0] - origin_x) / resolution
        fr = (outline[i, 1] - origin_y) / resolution
        if not (0.0 <= fc < w and 0.0 <= fr < h):
            return 254
        cols[i] = int(fc)
        rows[i] = int(fr)
    best = 0
    for i in range(m):
        j = (i + 1) % m
        v = _line_cost(cost, cols[i], rows[i], cols[j], rows[j])
        if v == 254:
            return 254
        if v > best:
            best = v
    return best


def footprint_cost(cost: NDArray[np.uint8], outline: NDArray[np.float64], origin: tuple[float, float], resolution: float) -> int:
    """Nav2's footprintCost: the highest cost along ``outline`` (M, 2 world points) on the grid ``cost``."""
    return int(_outline_cost(cost, np.ascontiguousarray(outline, dtype=np.float64), float(origin[0]), float(origin[1]), float(resolution)))


def warm_up() -> None:
    footprint_cost(np.zeros((4, 4), dtype=np.uint8), np.array([[0.05, 0.05], [0.15, 0.05], [0.1, 0.15]]), (0.0, 0.0), 0.05)
