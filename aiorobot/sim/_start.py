"""Where the simulated robot starts: the pose asked for, or the free spot nearest the world's start.

A start given explicitly (the simulator's ``start`` parameter, ``--start``) must leave the
robot's disc clear of obstacles and of the map's edge, or it is refused with the nearest
spot that would do. Without one the world's start is used (its YAML's ``start``, else the
origin), unless it is blocked or lies in unknown space: a Nav2 map (nav2_bringup's
``tb3_sandbox``, ``depot``...) has no start and its origin is often a map corner or
inside an obstacle, so the robot then starts on the known-free cell nearest to it, and
:attr:`StartChoice.warning` says so in one line.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ._world import World, WorldError

__all__ = ["StartChoice", "nearest_free_spot", "parse_start", "resolve_start"]

@dataclass(frozen=True, slots=True)
class StartChoice:
    """The start pose the robot gets, and the world's start it replaced (when it had to move)."""

    pose: tuple[float, float, float]
    #: the world's start that was blocked (None when the pose is the one asked for or the world's own)
    moved_from: tuple[float, float, float] | None = None
    #: why it moved: "inside an obstacle", "in unknown space"...
    reason: str = ""
    #: where the world came from (its YAML path or built-in name), for the warning
    world: str = ""

    @property
    def warning(self) -> str | None:
        """One line for the log when the start was moved, else None."""
        if self.moved_from is None:
            return None
        fx, fy, _ = self.moved_from
        what = "the origin" if (fx, fy) == (0.0, 0.0) else "the world's start"
        x, y, yaw = self.pose
        return (f"{self.world}: {what} ({fx:g}, {fy:g}) is {self.reason}; starting at the free cell nearest to it, "
                f"({x:g}, {y:g}, {yaw:g}); give a start (--start X,Y,YAW, or the simulator's start parameter) "
                "to choose another")


def parse_start(text: str) -> tuple[float, float, float]:
    """``"x,y"`` or ``"x,y,yaw"`` (m, m, rad) -> a start pose; ValueError saying what was expected."""
    parts = [p.strip() for p in text.split(",")]
    try:
        values = [float(p) for p in parts]
    except ValueError:
        values = []
    if len(values) not in (2, 3) or not all(math.isfinite(v) for v in values):
        raise ValueError(f"expected X,Y or X,Y,YAW numbers (m, m, rad) such as -2,0.5,1.57, found {text!r}")
    return (values[0], values[1], values[2] if len(values) == 3 else 0.0)


def _blocked(world: World, x: float, y: float, radius: float) -> str | None:
    """Why a disc of ``radius`` at ``(x, y)`` cannot hold the robot, or None when it can."""
    if not world.contains(x, y):
        ox, oy, _ = world.origin
        return (f"off the map (x {ox:g}..{ox + world.width_m:g}, y {oy:g}..{oy + world.height_m:g})")
    if world.is_free_disc(x, y, radius):
        return None
    ox, oy, _ = world.origin
    if min(x - ox, ox + world.width_m - x, y - oy, oy + world.height_m - y) <= radius:
        return f"within robot_radius {radius:g} m of the map's edge"
    return f"inside an obstacle (an occupied cell within robot_radius {radius:g} m)"


def _known_free_disc(world: World, x: float, y: float, radius: float) -> bool:
    """True when every cell within ``radius`` of ``(x, y)`` is on the map and free (neither occupied nor unknown)."""
    ox, oy, _ = world.origin
    res = world.resolution
    h, w = world.occupancy.shape
    c0, c1 = math.floor((x - radius - ox) / res), math.floor((x + radius - ox) / res)
    r0, r1 = math.floor((y - radius - oy) / res), math.floor((y + radius - oy) / res)
    if c0 < 0 or r0 < 0 or c1 >= w or r1 >= h:
        return False
    rows, cols = np.nonzero(world.occupancy[r0 : r1 + 1, c0 : c1 + 1] != 0)
    if rows.size == 0:
        return True
    cx0 = ox + (cols + c0) * res
    cy0 = oy + (rows + r0) * res
    dx = np.clip(x, cx0, cx0 + res) - x  # the nearest point of each such cell
    dy = np.clip(y, cy0, cy0 + res) - y
    return bool(np.all(dx * dx + dy * dy > radius * radius))


def nearest_free_spot(world: World, x: float, y: float, radius: float) -> tuple[float, float] | None:
    """The centre of the cell nearest ``(x, y)`` whose disc of ``radius`` holds only known-free cells.

    Known-free: occupancy 0 (neither occupied nor unknown), and wholly on the map. None when
    no cell qualifies.
    """
    import cv2

    blocked = np.pad(world.occupancy != 0, 1, constant_values=True)  # the border: the map's edge
    if blocked.all():
        return None
    # distance (cells) from each cell centre to the nearest blocked cell's centre; a blocked cell's nearest
    # point is no farther than its centre, so only cells where this exceeds the radius can qualify
    distance = cv2.distanceTransform(np.ascontiguousarray(~blocked, dtype=np.uint8), cv2.DIST_L2,
                                     cv2.DIST_MASK_PRECISE)[1:-1, 1:-1]
    res = world.resolution
    rows, cols = np.nonzero(distance * res > radius)
    ox, oy, _ = world.origin
    cx = ox + (cols + 0.5) * res
    cy = oy + (rows + 0.5) * res
    for i in np.argsort((cx - x) ** 2 + (cy - y) ** 2, kind="stable"):
        if _known_free_disc(world, float(cx[i]), float(cy[i]), radius):
            return float(cx[i]), float(cy[i])
    return None


def resolve_start(world: World, start: Sequence[float] | None, radius: float) -> StartChoice:
    """The robot's start in ``world``: ``start`` when given (checked), else the world's or the free spot nearest it.

    Raises :class:`WorldError` for a given start that is off the map or blocked, and for a
    world with no free spot at all; each names the fix.
    """
    where = world.path or world.name
    if start is not None:
        if len(start) != 3 or not all(math.isfinite(float(v)) for v in start):
            raise WorldError(f"start: expected [x, y, yaw] (m, m, rad), found {list(start)!r}")
        x, y, yaw = (float(v) for v in start)
        reason = _blocked(world, x, y, radius)
        if reason is not None:
            spot = nearest_free_spot(world, x, y, radius)
            hint = f"the nearest free spot is ({spot[0]:g}, {spot[1]:g})" if spot else "the map has no free spot"
            raise WorldError(f"{where}: start ({x:g}, {y:g}) is {reason}; {hint}")
        return StartChoice((x, y, yaw), world=where)
    x, y, yaw = world.start
    reason = _blocked(world, x, y, radius)
    if reason is None and not _known_free_disc(world, x, y, radius):
        reason = f"in unknown space (an unknown cell within robot_radius {radius:g} m)"
    if reason is None:
        return StartChoice(world.start, world=where)
    spot = nearest_free_spot(world, x, y, radius)
    if spot is None:
        raise WorldError(f"{where}: the start ({x:g}, {y:g}) is {reason}, and no known-free spot on the map holds "
                         f"a robot of radius {radius:g} m; check the map's free_thresh / negate")
    return StartChoice((spot[0], spot[1], yaw), moved_from=world.start, reason=reason, world=where)
