"""The collision monitor's model (nav2_collision_monitor) as a pure core.

Zones around the base, in its frame, each with an action (``CollisionMonitorState``'s codes):

- ``stop``: ``min_points`` or more obstacle points inside -> the command becomes zero;
- ``slowdown``: the command scaled by ``slowdown_ratio``;
- ``limit``: linear speed capped at ``linear_limit``, turn rate at ``angular_limit`` (one ratio
  for all components, so the curvature stays);
- ``approach``: the zone (the footprint) is carried along the commanded twist for up to
  ``time_before_collision`` s in ``simulation_time_step`` steps; a collision at ``t`` scales the
  command by ``t / time_before_collision``.

Zones are checked in order, as Nav2's ``CollisionMonitor::process``: a stop ends the checks, and
any other zone replaces the action only when its velocity is smaller (Nav2 compares
``x**2 + y**2 + wz**2``). A source without valid data (never received, older than its timeout,
not transformable) stops the base with polygon name ``"invalid source"``.
"""

from __future__ import annotations

import enum
import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

__all__ = ["ActionType", "CollisionAction", "CollisionMonitor", "Zone", "parse_points"]

#: the polygon name Nav2 reports when a source has no valid data
INVALID_SOURCE = "invalid source"


class ActionType(enum.IntEnum):
    """nav2_msgs ``CollisionMonitorState`` action codes."""

    DO_NOTHING = 0
    STOP = 1
    SLOWDOWN = 2
    APPROACH = 3
    LIMIT = 4

    @classmethod
    def from_parameter(cls, value: str, where: str) -> ActionType:
        """Nav2's ``action_type`` strings: stop, slowdown, limit, approach, none."""
        names = {"stop": cls.STOP, "slowdown": cls.SLOWDOWN, "limit": cls.LIMIT, "approach": cls.APPROACH, "none": cls.DO_NOTHING}
        if value not in names:
            raise ValueError(f"{where}: expected one of {', '.join(names)}, found {value!r}")
        return names[value]


def parse_points(value: str | Sequence[float], where: str, *, min_vertices: int = 3) -> NDArray[np.float64]:
    """A polygon's vertices (M, 2) from Nav2's ``points`` (or ``footprint``) parameter.

    Either Nav2's string form ``"[[x1, y1], [x2, y2], ...]"`` (Iron and later) or the flat
    double array ``[x1, y1, x2, y2, ...]`` (Humble). ``where`` names the parameter in errors.
    """
    if isinstance(value, str):
        try:
            rows = json.loads(value)
        except ValueError:
            raise ValueError(f"{where}: expected a list of [x, y] points such as \"[[0.3, 0.3], [0.3, -0.3], [0.0, 0.0]]\", "
                             f"found {value!r}") from None
        if not isinstance(rows, list) or not all(isinstance(r, list) and len(r) == 2 for r in rows):
            raise ValueError(f"{where}: expected a list of [x, y] points, found {value!r}")
        arr = np.asarray(rows, dtype=np.float64).reshape(-1, 2)
    else:
        flat = np.asarray(list(value), dtype=np.float64)
        if flat.size % 2:
            raise ValueError(f"{where}: expected an even number of values (x1, y1, x2, y2, ...), found {flat.size}")
        arr = flat.reshape(-1, 2)
    if len(arr) < min_vertices:
        raise ValueError(f"{where}: expected at least {min_vertices} points, found {len(arr)}")
    if not np.isfinite(arr).all():
        raise ValueError(f"{where}: expected finite coordinates, found {arr.tolist()}")
    return np.ascontiguousarray(arr)


@dataclass(frozen=True)
class Zone:
    """One of the monitor's polygons (Nav2 calls them polygons whatever their shape).

    ``vertices`` (M, 2) in the base frame, or ``radius`` > 0 for a circle about the base's
    origin. ``sources_names`` empty means every source, as Nav2's default.
    """

    name: str
    action_type: ActionType
    vertices: NDArray[np.float64] = field(default_factory=lambda: np.zeros((0, 2)))
    radius: float = 0.0
    min_points: int = 4
    slowdown_ratio: float = 0.5
    linear_limit: float = 0.5
    angular_limit: float = 0.5
    time_before_collision: float = 2.0
    simulation_time_step: float = 0.1
    enabled: bool = True
    sources_names: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        v = np.ascontiguousarray(self.vertices, dtype=np.float64).reshape(-1, 2)
        object.__setattr__(self, "vertices", v)
        where = f"collision monitor polygon {self.name!r}"
        if len(v) == 0 and not self.radius > 0:
            raise ValueError(f"{where}: expected points (3 or more) or a radius > 0, found neither")
        if 0 < len(v) < 3:
            raise ValueError(f"{where}: expected at least 3 points, found {len(v)}")
        if self.min_points < 1:
            raise ValueError(f"{where}: min_points must be >= 1, found {self.min_points}")
        if self.action_type == ActionType.APPROACH and not (self.simulation_time_step > 0 and self.time_before_collision > 0):
            raise ValueError(f"{where}: time_before_collision and simulation_time_step must be > 0, found "
                             f"{self.time_before_collision} and {self.simulation_time_step}")

    def inside(self, points: NDArray[np.float64]) -> NDArray[np.bool_]:
        """(N,) which of ``points`` (N, 2) lie inside the zone."""
        from ._collision_monitor_kernels import inside_mask

        return inside_mask(np.ascontiguousarray(points, dtype=np.float64).reshape(-1, 2), self.vertices, float(self.radius))

    def collision_time(self, points: NDArray[np.float64], velocity: tuple[float, float, float]) -> float:
        """Seconds before ``min_points`` points enter the zone moving at ``velocity``; -1 for never."""
        from ._collision_monitor_kernels import collision_time

        return float(collision_time(np.ascontiguousarray(points, dtype=np.float64).reshape(-1, 2), self.vertices, float(self.radius),
                                    int(self.min_points), float(velocity[0]), float(velocity[1]), float(velocity[2]),
                                    float(self.time_before_collision), float(self.simulation_time_step)))


@dataclass(frozen=True)
class CollisionAction:
    """The monitor's decision for one command: what, because of which zone, and the command to send."""

    action_type: ActionType
    polygon_name: str
    velocity: tuple[float, float, float]


def norm2(v: tuple[float, float, float]) -> float:
    """Nav2's velocity order (``Velocity::operator<``): ``vx**2 + vy**2 + wz**2``."""
    return v[0] * v[0] + v[1] * v[1] + v[2] * v[2]


def _scaled(v: tuple[float, float, float], k: float) -> tuple[float, float, float]:
    return (v[0] * k, v[1] * k, v[2] * k)


class CollisionMonitor:
    """Decide what happens to a velocity command given the obstacle points of each source.

    ``zones`` in the order Nav2 checks them (its ``polygons`` list).
    """

    def __init__(self, zones: Sequence[Zone]) -> None:
        names = [z.name for z in zones]
        if len(set(names)) != len(names):
            raise ValueError(f"collision monitor: polygon names must be unique, found {names}")
        self.zones = tuple(zones)

    def __repr__(self) -> str:
        return f"<CollisionMonitor {', '.join(f'{z.name}:{z.action_type.name.lower()}' for z in self.zones)}>"

    def decide(self, velocity: tuple[float, float, float], sources: Mapping[str, NDArray[np.float64] | None]) -> CollisionAction:
        """The action for the command ``velocity`` (vx, vy, wz) with ``sources``' points (N, 2) in
        the base frame; a source mapped to None has no valid data (the base stops)."""
        velocity = (float(velocity[0]), float(velocity[1]), float(velocity[2]))
        for points in sources.values():
            if points is None:
                return CollisionAction(ActionType.STOP, INVALID_SOURCE, (0.0, 0.0, 0.0))
        action = CollisionAction(ActionType.DO_NOTHING, "", velocity)
        for zone in self.zones:
            if not zone.enabled:
                continue
            points = self._points(zone, sources)
            if zone.action_type == ActionType.APPROACH:
                t = zone.collision_time(points, velocity) if len(points) else -1.0
                if t < 0.0:
                    continue
                safe = _scaled(velocity, t / zone.time_before_collision)
            elif zone.action_type == ActionType.DO_NOTHING:
                continue
            else:
                if int(np.count_nonzero(zone.inside(points))) < zone.min_points:
                    continue
                if zone.action_type == ActionType.STOP:
                    return CollisionAction(ActionType.STOP, zone.name, (0.0, 0.0, 0.0))
                if zone.action_type == ActionType.SLOWDOWN:
                    safe = _scaled(velocity, zone.slowdown_ratio)
                else:  # LIMIT: one ratio for every component keeps the curvature
                    ratio = 1.0
                    linear = math.hypot(velocity[0], velocity[1])
                    if linear != 0.0:
                        ratio = min(ratio, zone.linear_limit / linear)
                    if velocity[2] != 0.0:
                        ratio = min(ratio, zone.angular_limit / abs(velocity[2]))
                    safe = _scaled(velocity, min(max(ratio, 0.0), 1.0))
            if norm2(safe) < norm2(action.velocity):
                action = CollisionAction(zone.action_type, zone.name, safe)
        return action

    @staticmethod
    def _points(zone: Zone, sources: Mapping[str, NDArray[np.float64] | None]) -> NDArray[np.float64]:
        chosen = [p for name, p in sources.items() if p is not None and (not zone.sources_names or name in zone.sources_names)]
        if not chosen:
            return np.zeros((0, 2))
        return chosen[0] if len(chosen) == 1 else np.concatenate(chosen)
