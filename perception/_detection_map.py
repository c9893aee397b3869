"""The camera + lidar detection map: markers and obstacles in one frame, one state, one guard."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from aiorobot import MutuallyExclusiveCallbackGroup, Node

__all__ = ["DetectionMap", "DetectionMapNode", "MapMarker"]


@dataclass
class MapMarker:
    """A landmark: running mean of its positions in the map frame, and how often it was seen."""

    marker_id: int
    position: NDArray[np.float64]
    sightings: int = 1


@dataclass
class DetectionMap:
    """Markers (by id, averaged) and the latest lidar obstacles ((K, 3) x, y, z rows), in one frame."""

    frame_id: str
    markers: dict[int, MapMarker] = field(default_factory=dict)
    obstacles: NDArray[np.float64] = field(default_factory=lambda: np.zeros((0, 3)))
    updates: int = 0

    def add_markers(self, ids: list[int], positions: NDArray[np.float64]) -> None:
        """Fold (N, 3) marker positions (map frame) into the running means."""
        for marker_id, position in zip(ids, positions):
            known = self.markers.get(marker_id)
            if known is None:
                self.markers[marker_id] = MapMarker(marker_id, np.array(position, dtype=np.float64))
            else:
                known.sightings += 1
                known.position += (position - known.position) / known.sightings
        self.updates += 1

    def set_obstacles(self, obstacles: NDArray[np.float64]) -> None:
        """Replace the obstacles with the latest scan's (K, 3) rows (map frame)."""
        self.obstacles = np.asarray(obstacles, dtype=np.float64).reshape(-1, 3)
        self.updates += 1


class DetectionMapNode(Node):
    """Camera markers and lidar obstacles in one map, transformed through tf at each message's stamp.

    Subscribes ``markers_topic`` (aiorobot_msgs/MarkerDetectionArray, camera frame) and
    ``obstacles_topic`` (PoseArray, laser frame); publishes ``/detection_map/markers`` and
    ``/detection_map/obstacles`` (PoseArray in ``map_frame``). Both callbacks share one
    mutually exclusive callback group: the map is never updated by two at once, even
    across their awaits on tf. A message whose transform does not arrive within
    ``tf_timeout_sec`` is dropped and counted.
    """

    def __init__(self, name: str = "detection_map", **node_kwargs: Any) -> None:
        from aiorobot.msgs.geometry_msgs import PoseArray
        from aiorobot.tf import Buffer, TransformListener

        from ._msgs import MarkerDetectionArray

        super().__init__(name, **node_kwargs)
        self.map_frame = self.declare_parameter("map_frame", "map", read_only=True).value
        self.tf_timeout_sec = float(self.declare_parameter("tf_timeout_sec", 0.5).value)
        markers_topic = self.declare_parameter("markers_topic", "/detections/markers", read_only=True).value
        obstacles_topic = self.declare_parameter("obstacles_topic", "/obstacles", read_only=True).value
        self.state = DetectionMap(self.map_frame)
        self.dropped = 0
        self.buffer = Buffer()
        self.listener = TransformListener(self.buffer, self)
        self.group = MutuallyExclusiveCallbackGroup()
        self.markers_pub = self.create_publisher(PoseArray, "/detection_map/markers", 10)
        self.obstacles_pub = self.create_publisher(PoseArray, "/detection_map/obstacles", 10)
        self.create_subscription(MarkerDetectionArray, markers_topic, self.on_markers, 10, callback_group=self.group)
        self.create_subscription(PoseArray, obstacles_topic, self.on_obstacles, 10, callback_group=self.group)

    async def _to_map(self, header: Any, points: NDArray[np.float64]) -> NDArray[np.float64] | None:
        from aiorobot.tf import TransformException

        try:
            await self.buffer.wait_for_transform(self.map_frame, header.frame_id, header.stamp, self.tf_timeout_sec)
            return self.buffer.transform_points(points, self.map_frame, header.frame_id, header.stamp)
        except TransformException as exc:
            self.dropped += 1
            self.get_logger().warning(f"detection map: dropped a message from {header.frame_id!r}: {exc} "
                                      f"({self.dropped} dropped so far)", throttle_duration_sec=5.0)
            return None

    async def on_markers(self, msg: Any) -> None:
        if not msg.detections:
            return
        ids = [d.marker_id for d in msg.detections]
        camera = np.array([[d.pose.position.x, d.pose.position.y, d.pose.position.z] for d in msg.detections])
        in_map = await self._to_map(msg.header, camera)
        if in_map is not None:
            new = [i for i in ids if i not in self.state.markers]
            self.state.add_markers(ids, in_map)
            for marker_id in new:
                x, y, z = self.state.markers[marker_id].position
                self.get_logger().info(f"detection map: marker {marker_id} at ({x:.2f}, {y:.2f}, {z:.2f}) "
                                       f"in {self.map_frame}")
            self._publish(msg.header.stamp)

    async def on_obstacles(self, msg: Any) -> None:
        centres = np.array([[p.position.x, p.position.y, p.position.z] for p in msg.poses]).reshape(-1, 3)
        in_map = await self._to_map(msg.header, centres)
        if in_map is not None:
            self.state.set_obstacles(in_map)
            self._publish(msg.header.stamp)

    def _publish(self, stamp: Any) -> None:
        from aiorobot.msgs.geometry_msgs import Pose, PoseArray

        for pub, rows in ((self.markers_pub, [m.position for m in sorted(self.state.markers.values(),
                                                                           key=lambda m: m.marker_id)]),
                          (self.obstacles_pub, list(self.state.obstacles))):
            out = PoseArray()
            out.header.frame_id = self.map_frame
            out.header.stamp = stamp
            for row in rows:
                pose = Pose()
                pose.position.x, pose.position.y = float(row[0]), float(row[1])
                pose.position.z = float(row[2])
                out.poses.append(pose)
            pub.publish(out)
