"""Online occupancy-grid mapping from scans with known poses (log-odds), and its node.

The pure core :class:`OccupancyMapper` keeps a log-odds grid; each scan (laser pose in the map
frame + ranges) lowers the log-odds of the cells a beam crosses and raises the cell it ends in.
:meth:`OccupancyMapper.to_map` thresholds it into an OccupancyGrid (free < 0.2 < unknown < 0.65 <
occupied, probabilities). ``MappingNode`` feeds it from ``/scan`` with the pose from tf
(``map_frame`` -> the scan's frame), publishes ``/map`` and saves with :func:`save_map`.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .._core._node import Node
from .._core._warm_up import compile_kernels
from .._core._qos import QoSProfile, ReliabilityPolicy
from ._map_server import MAP_QOS
from ._maps import OccupancyMap

__all__ = ["MappingNode", "OccupancyMapper"]


def _logit(p: float) -> float:
    return math.log(p / (1.0 - p))


class OccupancyMapper:
    """A log-odds occupancy grid of ``size_m`` (w, h) metres at ``resolution``, lower-left at ``origin``."""

    def __init__(self, size_m: tuple[float, float], resolution: float, origin: tuple[float, float], *,
                 p_hit: float = 0.7, p_miss: float = 0.4, p_min: float = 0.12, p_max: float = 0.97) -> None:
        if not resolution > 0 or min(size_m) <= 0:
            raise ValueError(f"mapper: resolution and size must be > 0, found {resolution}, {size_m}")
        w = int(math.ceil(size_m[0] / resolution))
        h = int(math.ceil(size_m[1] / resolution))
        self.logodds = np.zeros((h, w), dtype=np.float64)
        self.resolution = float(resolution)
        self.origin = (float(origin[0]), float(origin[1]))
        self.l_occ, self.l_free = _logit(p_hit), _logit(p_miss)
        self.l_min, self.l_max = _logit(p_min), _logit(p_max)
        self.scans = 0

    def integrate(self, laser_pose: tuple[float, float, float], ranges: NDArray[np.float64], angle_min: float,
                  angle_increment: float, range_min: float, range_max: float) -> None:
        """Add one scan taken from ``laser_pose`` (x, y, yaw in the map frame)."""
        from ._kernels import integrate_scan

        r = np.asarray(ranges, dtype=np.float64)
        finite = np.isfinite(r)
        hit = finite & (r >= range_min) & (r < range_max)
        use = finite & (r >= range_min)
        lengths = np.where(hit, r, range_max)
        angles = laser_pose[2] + angle_min + np.arange(len(r)) * angle_increment
        pts = np.column_stack([laser_pose[0] + lengths * np.cos(angles), laser_pose[1] + lengths * np.sin(angles)])[use]
        integrate_scan(self.logodds, float(laser_pose[0]), float(laser_pose[1]), np.ascontiguousarray(pts), hit[use],
                       self.origin[0], self.origin[1], self.resolution, self.l_free, self.l_occ, self.l_min, self.l_max)
        self.scans += 1

    def probabilities(self) -> NDArray[np.float64]:
        return 1.0 - 1.0 / (1.0 + np.exp(self.logodds))

    def to_map(self, frame_id: str = "map") -> OccupancyMap:
        p = self.probabilities()
        data = np.full(p.shape, -1, dtype=np.int8)
        data[p < 0.2] = 0
        data[p > 0.65] = 100
        return OccupancyMap(data, self.resolution, (self.origin[0], self.origin[1], 0.0), frame_id)


class MappingNode(Node):
    """Maps from ``/scan`` with known poses. Parameters: ``map_frame`` (map), ``resolution`` (0.05),
    ``size_x``/``size_y`` (m, default 20), ``origin_x``/``origin_y`` (default -10), ``publish_period`` (s, 1.0)."""

    def __init__(self, node_name: str = "mapper", **kwargs: Any) -> None:
        super().__init__(node_name, **kwargs)
        d = self.declare_parameter
        self.map_frame = str(d("map_frame", "map").value)
        self.mapper = OccupancyMapper((float(d("size_x", 20.0).value), float(d("size_y", 20.0).value)),
                                      float(d("resolution", 0.05).value),
                                      (float(d("origin_x", -10.0).value), float(d("origin_y", -10.0).value)))
        from aiorobot.msgs.nav_msgs import OccupancyGrid
        from aiorobot.msgs.sensor_msgs import LaserScan
        from aiorobot.tf import Buffer, TransformListener

        self.buffer = Buffer()
        self.listener = TransformListener(self.buffer, self)
        self.skipped = 0
        self.create_subscription(LaserScan, "/scan", self._on_scan, QoSProfile(reliability=ReliabilityPolicy.BEST_EFFORT, depth=5))
        self.pub = self.create_publisher(OccupancyGrid, "/map", MAP_QOS)
        self.create_timer(float(d("publish_period", 1.0).value), self.publish_map)
        from ._kernels import warm_up

        compile_kernels(self.get_logger(), lambda: warm_up("integrate_scan"))  # not at the first scan

    def _on_scan(self, scan: Any) -> None:
        from aiorobot import Time
        from aiorobot.tf import TransformException

        from ._geometry import transform_to_xyyaw

        try:
            t = self.buffer.lookup_transform(self.map_frame, scan.header.frame_id, Time.from_msg(scan.header.stamp))
        except TransformException as err:
            self.skipped += 1
            self.get_logger().warning(f"mapping: no pose for the scan ({err})", throttle_duration_sec=2.0)
            return
        self.mapper.integrate(transform_to_xyyaw(t), np.asarray(scan.ranges), float(scan.angle_min), float(scan.angle_increment),
                              float(scan.range_min), float(scan.range_max))

    def publish_map(self) -> None:
        if self.mapper.scans:
            self.pub.publish(self.mapper.to_map(self.map_frame).to_msg(self.now().to_msg()))
