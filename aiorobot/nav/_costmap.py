"""Costmaps with Nav2's cell values, layers and inflation cost function.

Cells hold Nav2's ``nav2_costmap_2d`` costs: ``FREE_SPACE`` 0, ``INSCRIBED_INFLATED_OBSTACLE``
253, ``LETHAL_OBSTACLE`` 254, ``NO_INFORMATION`` 255. Row ``r`` column ``c`` is the cell whose
lower-left corner is ``origin + (c, r) * resolution`` (the OccupancyGrid layout, REP 103 map frame).

Layers, as Nav2's: the static layer (from an OccupancyGrid: occupied -> lethal, unknown -> no
information unless ``track_unknown_space`` is false), the obstacle layer (scan endpoints marked
lethal, the cells along each beam cleared), and inflation with Nav2's cost function:

    distance 0                        -> LETHAL_OBSTACLE
    distance <= inscribed_radius      -> INSCRIBED_INFLATED_OBSTACLE
    distance <= inflation_radius      -> (INSCRIBED - 1) * exp(-cost_scaling_factor * (distance - inscribed_radius))

with ``distance`` the Euclidean distance between cell centres (InflationLayer::computeCost).

The robot's shape is a :class:`~aiorobot.nav.Footprint` (Nav2's ``footprint`` polygon or
``robot_radius``): its inscribed radius is inflation's ``inscribed_radius``, and
:meth:`Costmap.in_collision` checks a pose with it. A keepout filter's mask (Nav2's
KeepoutFilter costs) is merged into the static layer before inflation, unlike Nav2, which applies
filters after it: a keepout zone then keeps the robot's body out, not only its centre, and the
controller's collision check does not stop the robot on a path hugging the zone's edge.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

if TYPE_CHECKING:
    from ._footprint import Footprint

__all__ = [
    "FREE_SPACE",
    "INSCRIBED_INFLATED_OBSTACLE",
    "LETHAL_OBSTACLE",
    "NO_INFORMATION",
    "Costmap",
    "inflation_cost",
]

FREE_SPACE = 0
INSCRIBED_INFLATED_OBSTACLE = 253
LETHAL_OBSTACLE = 254
NO_INFORMATION = 255


def inflation_cost(distance_m: NDArray[np.float64] | float, inscribed_radius: float, cost_scaling_factor: float) -> NDArray[np.uint8]:
    """Nav2's inflation cost for a distance (m) to the nearest lethal cell; truncated to uint8 as Nav2 does."""
    d = np.asarray(distance_m, dtype=np.float64)
    factor = np.exp(-cost_scaling_factor * (d - inscribed_radius))
    cost = np.floor((INSCRIBED_INFLATED_OBSTACLE - 1) * factor)
    cost = np.where(d <= inscribed_radius, INSCRIBED_INFLATED_OBSTACLE, cost)
    cost = np.where(d <= 0.0, LETHAL_OBSTACLE, cost)
    return np.clip(cost, 0, 255).astype(np.uint8)


@dataclass
class Costmap:
    """A 2D costmap: ``cost`` (H, W) uint8, ``resolution`` (m/cell), ``origin`` (x, y) of cell (0, 0)'s corner.

    Parameters as Nav2's: ``robot_radius`` (inscribed radius of a round footprint),
    ``inflation_radius``, ``cost_scaling_factor``. A ``footprint`` (a :class:`Footprint`) sets
    ``robot_radius`` to its inscribed radius; without one the robot is the disc of ``robot_radius``.
    """

    static: NDArray[np.uint8]
    resolution: float
    origin: tuple[float, float]
    robot_radius: float = 0.22
    inflation_radius: float = 0.55
    cost_scaling_factor: float = 3.0
    footprint: Footprint | None = None

    def __post_init__(self) -> None:
        from ._footprint import Footprint

        if self.footprint is None:
            self.footprint = Footprint.circle(self.robot_radius)
        else:
            self.robot_radius = self.footprint.inscribed_radius
        self.static = np.ascontiguousarray(self.static, dtype=np.uint8)
        if self.static.ndim != 2 or min(self.static.shape) < 1:
            raise ValueError(f"costmap: expected a (H, W) grid, got shape {self.static.shape}")
        if not self.resolution > 0:
            raise ValueError(f"costmap: resolution must be > 0, found {self.resolution}")
        if self.inflation_radius < self.robot_radius:
            raise ValueError(
                f"costmap: inflation_radius ({self.inflation_radius}) must be >= robot_radius ({self.robot_radius}), as in Nav2"
            )
        #: the keepout filter's costs on this grid (NO_INFORMATION: no say), merged into the static layer
        self.keepout: NDArray[np.uint8] | None = None
        self.obstacles = np.zeros_like(self.static)
        self.cost = np.empty_like(self.static)
        self._static_cost: NDArray[np.uint8] | None = None
        self.update()

    @classmethod
    def from_occupancy(cls, data: NDArray[np.int8], width: int, height: int, resolution: float, origin: tuple[float, float],
                       *, track_unknown_space: bool = True, lethal_threshold: int = 100, **params: float) -> Costmap:
        """The static layer from OccupancyGrid data (-1 unknown, 0..100), as Nav2's StaticLayer."""
        grid = np.asarray(data, dtype=np.int16).reshape(height, width)
        static = np.full(grid.shape, FREE_SPACE, dtype=np.uint8)
        static[grid >= lethal_threshold] = LETHAL_OBSTACLE
        if track_unknown_space:
            static[grid < 0] = NO_INFORMATION
        return cls(static, resolution, origin, **params)

    @property
    def shape(self) -> tuple[int, int]:
        return self.static.shape  # type: ignore[return-value]

    def world_to_cell(self, x: float, y: float) -> tuple[int, int]:
        """(row, col) of the cell holding world point (x, y); may be outside the grid."""
        return int(math.floor((y - self.origin[1]) / self.resolution)), int(math.floor((x - self.origin[0]) / self.resolution))

    def cell_to_world(self, row: float, col: float) -> tuple[float, float]:
        """World (x, y) of a cell's centre."""
        return self.origin[0] + (col + 0.5) * self.resolution, self.origin[1] + (row + 0.5) * self.resolution

    def in_bounds(self, row: int, col: int) -> bool:
        return 0 <= row < self.shape[0] and 0 <= col < self.shape[1]

    def cost_at(self, x: float, y: float) -> int:
        """Cost of the cell under (x, y); NO_INFORMATION outside the map."""
        r, c = self.world_to_cell(x, y)
        return int(self.cost[r, c]) if self.in_bounds(r, c) else NO_INFORMATION

    def footprint_cost(self, x: float, y: float, yaw: float) -> int:
        """Nav2's ``footprintCostAtPose``: the highest cost along the footprint's outline at (x, y, yaw)."""
        from ._footprint import footprint_cost

        assert self.footprint is not None
        return footprint_cost(self.cost, self.footprint.at(x, y, yaw), self.origin, self.resolution)

    def in_collision(self, x: float, y: float, yaw: float, *, allow_unknown: bool = True) -> bool:
        """Whether the robot at (x, y, yaw) touches an obstacle.

        A round robot: its centre cell is INSCRIBED or LETHAL (an obstacle within the radius).
        A polygon: that, or a LETHAL cell on its outline (Nav2's RPP check). Unknown space counts
        as free with ``allow_unknown`` (Nav2's track_unknown_space), else as an obstacle.
        """
        centre = self.cost_at(x, y)
        if centre == NO_INFORMATION:
            if not allow_unknown:
                return True
        elif centre >= INSCRIBED_INFLATED_OBSTACLE:
            return True
        assert self.footprint is not None
        if self.footprint.is_circular:
            return False
        outline = self.footprint_cost(x, y, yaw)
        return outline == LETHAL_OBSTACLE or (outline == NO_INFORMATION and not allow_unknown)

    def clear_obstacles(self) -> None:
        self.obstacles[:] = 0

    def mark_scan(self, origin_xy: tuple[float, float], endpoints_xy: NDArray[np.float64], hit: NDArray[np.bool_],
                  *, obstacle_max_range: float = 2.5, raytrace_max_range: float = 3.0) -> None:
        """Obstacle layer: clear along each beam (up to ``raytrace_max_range``), mark hits within
        ``obstacle_max_range`` lethal. ``endpoints_xy`` (N, 2) world points, ``hit`` (N,) True for a real return."""
        from ._kernels import raytrace_clear

        pts = np.ascontiguousarray(endpoints_xy, dtype=np.float64).reshape(-1, 2)
        hits = np.asarray(hit, dtype=np.bool_).reshape(-1)
        if hits.shape[0] != pts.shape[0]:
            raise ValueError(f"mark_scan: {pts.shape[0]} endpoints but {hits.shape[0]} hit flags")
        raytrace_clear(self.obstacles, float(origin_xy[0]), float(origin_xy[1]), pts, hits, float(self.origin[0]),
                       float(self.origin[1]), float(self.resolution), float(obstacle_max_range), float(raytrace_max_range))

    def update(self) -> None:
        """Combine static and obstacle layers, then inflate (Nav2's layer order).

        The inflated static layer is computed once. Inflating the union of two sets of lethal
        cells is the cell-wise maximum of inflating each (the cost falls with distance), so an
        update only inflates the obstacle layer, inside the window its marks can reach.
        """
        if self._static_cost is None or self._static_cost.shape != self.static.shape:
            self._static_cost = self._inflate(self._with_keepout(self.static))
        cost = self._static_cost.copy()
        marks = np.argwhere(self.obstacles == LETHAL_OBSTACLE)
        if len(marks):
            pad = int(math.ceil(self.inflation_radius / self.resolution)) + 1
            r0, c0 = np.maximum(marks.min(axis=0) - pad, 0)
            r1, c1 = np.minimum(marks.max(axis=0) + pad + 1, self.static.shape)
            window = self._inflate(self.obstacles[r0:r1, c0:c1])
            sub = cost[r0:r1, c0:c1]
            merged = np.maximum(sub, window)
            merged[sub == NO_INFORMATION] = NO_INFORMATION  # unknown stays unknown (Nav2's inflate_unknown: false)...
            merged[self.obstacles[r0:r1, c0:c1] == LETHAL_OBSTACLE] = LETHAL_OBSTACLE  # ...unless an obstacle was seen there
            cost[r0:r1, c0:c1] = merged
        self.cost = cost

    def _with_keepout(self, layer: NDArray[np.uint8]) -> NDArray[np.uint8]:
        """``layer`` under the keepout filter: Nav2's KeepoutFilter rule, a mask cost replaces a lower or unknown one."""
        if self.keepout is None:
            return layer
        out = layer.copy()
        k = self.keepout
        take = (k != NO_INFORMATION) & ((k > out) | (out == NO_INFORMATION))
        out[take] = k[take]
        return out

    def set_keepout(self, layer: NDArray[np.uint8] | None) -> None:
        """Install (or with None remove) a keepout filter layer (H, W) of costs, see
        :func:`~aiorobot.nav.keepout_layer`, and recompute the costs."""
        if layer is not None:
            layer = np.ascontiguousarray(layer, dtype=np.uint8)
            if layer.shape != self.static.shape:
                raise ValueError(f"set_keepout: expected a layer of the costmap's shape {self.static.shape}, found {layer.shape}")
        self.keepout = layer
        self._static_cost = None
        self.update()

    def _inflate(self, layer: NDArray[np.uint8]) -> NDArray[np.uint8]:
        """``layer`` with its lethal cells inflated (cells outside ``inflation_radius`` keep their value)."""
        import cv2

        lethal = layer == LETHAL_OBSTACLE
        cost = layer.copy()
        if not lethal.any():
            return cost
        # Distance from every cell centre to the nearest lethal cell centre (exact Euclidean).
        dist = cv2.distanceTransform((~lethal).astype(np.uint8), cv2.DIST_L2, cv2.DIST_MASK_PRECISE)
        within = (dist <= (self.inflation_radius + 1e-9) / self.resolution) & (layer != NO_INFORMATION)
        if within.any():
            inflated = inflation_cost(dist[within].astype(np.float64) * self.resolution, self.robot_radius, self.cost_scaling_factor)
            cost[within] = np.maximum(cost[within], inflated)
        return cost

    def to_occupancy(self) -> NDArray[np.int8]:
        """The costmap as OccupancyGrid data (Nav2's costmap topic scaling: 0..100, -1 unknown)."""
        out = np.round(self.cost.astype(np.float64) * 100.0 / 253.0).astype(np.int16)
        out[self.cost >= INSCRIBED_INFLATED_OBSTACLE] = 100
        out[self.cost == INSCRIBED_INFLATED_OBSTACLE] = 99
        out[self.cost == NO_INFORMATION] = -1
        return out.astype(np.int8).reshape(-1)
