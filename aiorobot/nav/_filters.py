"""Costmap filters as nav2_costmap_2d's: keepout zones and speed limits from a filter mask.

A filter is an OccupancyGrid mask plus a nav2_msgs/CostmapFilterInfo (``type``,
``filter_mask_topic``, ``base``, ``multiplier``), Nav2's convention (``filter_values.hpp``):

- ``KEEPOUT_FILTER`` (0): each mask cell becomes a cost, ``round(value * 254 / 100)`` (unknown ->
  NO_INFORMATION, skipped); the costmap cell takes it where it is higher or the cell is unknown
  (``KeepoutFilter::process``), after inflation. A mask of 100 is LETHAL: planners route around.
- ``SPEED_FILTER_PERCENT`` (1) / ``SPEED_FILTER_ABSOLUTE`` (2): at the robot's cell the limit is
  ``base + multiplier * value`` in percent of the controller's speed or in m/s; a value of 0 is
  no limit (``NO_SPEED_LIMIT``), -1 (unknown) is an error in the mask; a percentage outside
  [0, 100] or a negative speed is no limit, with a warning (``SpeedFilter::getSpeedLimitAtPose``).

Masks are looked up by world position (cell centres of the costmap), so a mask may have its own
resolution and origin; it must be in the costmap's frame.
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ._costmap import LETHAL_OBSTACLE, NO_INFORMATION, Costmap
from ._maps import OccupancyMap

__all__ = ["NO_SPEED_LIMIT", "FilterType", "SpeedLimitFilter", "keepout_cost_at", "keepout_layer", "limited_speed", "mask_cost"]

#: nav2_costmap_2d's NO_SPEED_LIMIT: a speed limit of 0.0 means none
NO_SPEED_LIMIT = 0.0


class FilterType(enum.IntEnum):
    """CostmapFilterInfo ``type`` values (nav2_costmap_2d ``filter_values.hpp``)."""

    KEEPOUT_FILTER = 0
    SPEED_FILTER_PERCENT = 1
    SPEED_FILTER_ABSOLUTE = 2
    BINARY_FILTER = 3


def mask_cost(values: NDArray[np.int8]) -> NDArray[np.uint8]:
    """Nav2's ``getMaskCost``: OccupancyGrid values (-1, 0..100) -> costs (NO_INFORMATION, 0..254)."""
    v = np.asarray(values, dtype=np.float64)
    cost = np.round(v * LETHAL_OBSTACLE / 100.0)
    return np.where(v < 0, NO_INFORMATION, np.clip(cost, 0, LETHAL_OBSTACLE)).astype(np.uint8)


def _mask_values(mask: OccupancyMap, x: NDArray[np.float64], y: NDArray[np.float64]) -> NDArray[np.int16]:
    """The mask's values at world points; -2 where a point is off the mask."""
    if mask.origin[2] != 0.0:
        raise ValueError(f"filter mask: expected an origin with yaw 0 (as the costmap's), found yaw {mask.origin[2]:g}")
    c = np.floor((x - mask.origin[0]) / mask.resolution).astype(np.int64)
    r = np.floor((y - mask.origin[1]) / mask.resolution).astype(np.int64)
    on = (r >= 0) & (r < mask.height) & (c >= 0) & (c < mask.width)
    out = np.full(np.shape(x), -2, dtype=np.int16)
    out[on] = mask.data[r[on], c[on]]
    return out


def keepout_layer(costmap: Costmap, mask: OccupancyMap) -> NDArray[np.uint8]:
    """The keepout mask as costs on the costmap's grid (H, W): NO_INFORMATION where the mask is
    unknown or absent (those cells are left alone)."""
    h, w = costmap.shape
    cols, rows = np.meshgrid(np.arange(w), np.arange(h))
    x = costmap.origin[0] + (cols + 0.5) * costmap.resolution
    y = costmap.origin[1] + (rows + 0.5) * costmap.resolution
    values = _mask_values(mask, x, y)
    return mask_cost(np.where(values < -1, -1, values).astype(np.int8))


def keepout_cost_at(mask: OccupancyMap, x: float, y: float) -> int:
    """The keepout mask's cost at world point (x, y) (NO_INFORMATION off the mask or unknown)."""
    value = int(_mask_values(mask, np.array([x]), np.array([y]))[0])
    return int(mask_cost(np.array([max(value, -1)], np.int8))[0])


@dataclass(frozen=True)
class SpeedLimitFilter:
    """A speed mask and its filter info: the limit at a position (Nav2's SpeedFilter)."""

    mask: OccupancyMap
    type: FilterType
    base: float = 0.0
    multiplier: float = 1.0

    def __post_init__(self) -> None:
        if self.type not in (FilterType.SPEED_FILTER_PERCENT, FilterType.SPEED_FILTER_ABSOLUTE):
            raise ValueError(f"speed filter: expected CostmapFilterInfo type {int(FilterType.SPEED_FILTER_PERCENT)} "
                             f"(percent) or {int(FilterType.SPEED_FILTER_ABSOLUTE)} (m/s), found {int(self.type)}")

    @property
    def percentage(self) -> bool:
        return self.type == FilterType.SPEED_FILTER_PERCENT

    def limit_at(self, x: float, y: float) -> float:
        """The limit at (x, y): percent or m/s; NO_SPEED_LIMIT (0.0) for none or off the mask.

        Raises ValueError on an unknown (-1) mask cell, which Nav2 reports as invalid for this filter.
        """
        value = int(_mask_values(self.mask, np.array([x]), np.array([y]))[0])
        if value == -2 or value == 0:
            return NO_SPEED_LIMIT
        if value == -1:
            raise ValueError(f"speed filter: the mask is unknown (-1) at ({x:.2f}, {y:.2f}), which is invalid for a speed "
                             f"mask; use 0 for no limit")
        limit = value * self.multiplier + self.base
        if (self.percentage and not 0.0 <= limit <= 100.0) or (not self.percentage and limit < 0.0):
            return NO_SPEED_LIMIT
        return float(limit)


def limited_speed(base_speed: float, speed_limit: float, percentage: bool) -> float:
    """Nav2 controllers' ``setSpeedLimit``: the desired speed under ``speed_limit`` (NO_SPEED_LIMIT: ``base_speed``)."""
    if speed_limit == NO_SPEED_LIMIT or not math.isfinite(speed_limit):
        return base_speed
    return base_speed * speed_limit / 100.0 if percentage else speed_limit
