"""The lidar side: LaserScan -> points -> segments -> obstacles (Numba, off the event loop), published."""

from __future__ import annotations

from typing import Any

import numpy as np

from aiorobot import Node, compile_kernels

from ._cloud import xyz_to_cloud
from ._images import BadInput
from ._scan import extract_obstacles, scan_to_points, segment_scan, warm_up

__all__ = ["ScanObstacleNode", "scan_obstacles"]


def scan_obstacles(msg: Any, break_distance: float, min_points: int) -> tuple[np.ndarray, np.ndarray]:
    """Points (N, 2) and obstacles (K, 4: x, y, radius, count) of one LaserScan, in its frame."""
    points = scan_to_points(msg)
    labels = segment_scan(points, break_distance, min_points)
    return points, extract_obstacles(points, labels)


class ScanObstacleNode(Node):
    """Clusters of a LaserScan as obstacles: ``/obstacles`` (PoseArray, one pose per cluster centre) and
    ``/scan/points`` (PointCloud2), both in the scan's frame, stamped with the scan's stamp.

    Parameters: ``scan_topic`` (/scan), ``obstacles_topic`` (/obstacles), ``points_topic``
    (/scan/points), ``break_distance`` (m, 0.2), ``min_points`` (3), ``max_radius`` (m, 1.0:
    larger segments are walls, not obstacles). The Numba kernels run in the thread pool
    with the GIL released. Bad scans are dropped, counted and warned about.
    """

    def __init__(self, name: str = "scan_obstacles", **node_kwargs: Any) -> None:
        from aiorobot.msgs.geometry_msgs import PoseArray
        from aiorobot.msgs.sensor_msgs import LaserScan, PointCloud2

        super().__init__(name, **node_kwargs)
        scan_topic = self.declare_parameter("scan_topic", "/scan", read_only=True).value
        self.break_distance = float(self.declare_parameter("break_distance", 0.2).value)
        self.min_points = int(self.declare_parameter("min_points", 3).value)
        self.max_radius = float(self.declare_parameter("max_radius", 1.0).value)
        self.obstacles_pub = self.create_publisher(
            PoseArray, self.declare_parameter("obstacles_topic", "/obstacles", read_only=True).value, 10)
        self.points_pub = self.create_publisher(
            PointCloud2, self.declare_parameter("points_topic", "/scan/points", read_only=True).value, 10)
        self.scan_topic = scan_topic
        self.dropped = 0
        self.processed = 0
        self.create_subscription(LaserScan, scan_topic, self.on_scan, 5)
        compile_kernels(self.get_logger(), warm_up)  # not in the first scan's callback

    async def on_scan(self, msg: Any) -> None:
        from aiorobot.msgs.geometry_msgs import Pose, PoseArray

        if self.runtime.is_shutdown:  # scans still queued while the runtime closes: the thread pool is gone
            return
        try:
            points, obstacles = await self.run_in_thread(scan_obstacles, msg, self.break_distance, self.min_points)
        except BadInput as exc:
            self.dropped += 1
            self.get_logger().warning(f"{self.scan_topic}: dropped a scan: {exc} ({self.dropped} dropped so far)",
                                      throttle_duration_sec=5.0)
            return
        self.processed += 1
        out = PoseArray()
        out.header = msg.header
        for x, y, radius, _ in obstacles:
            if radius <= self.max_radius:
                pose = Pose()
                pose.position.x, pose.position.y = float(x), float(y)
                out.poses.append(pose)
        self.obstacles_pub.publish(out)
        self.points_pub.publish(xyz_to_cloud(points, msg.header.frame_id, msg.header.stamp))
