"""``MapServer``: publishes a map_server YAML map on ``/map`` (transient local), as nav2_map_server."""

from __future__ import annotations

from typing import Any

from .._core._node import Node
from .._core._qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from ._maps import load_map

__all__ = ["MAP_QOS", "MapServer"]

#: /map's QoS in Nav2: reliable, transient local, depth 1 (late joiners get the map).
MAP_QOS = QoSProfile(reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL, depth=1)


class MapServer(Node):
    """Parameters: ``yaml_filename`` (the map), ``topic_name`` (default ``map``), ``frame_id`` (``map``)."""

    def __init__(self, node_name: str = "map_server", *, yaml_filename: str = "", **kwargs: Any) -> None:
        super().__init__(node_name, **kwargs)
        path = str(self.declare_parameter("yaml_filename", yaml_filename).value)
        topic = str(self.declare_parameter("topic_name", "map").value)
        frame = str(self.declare_parameter("frame_id", "map").value)
        if not path:
            raise ValueError(f"map server {self.get_name()}: parameter 'yaml_filename' (a map_server YAML) is required")
        self.map, self.document = load_map(path)  # a bad file fails here, before anything starts
        self.map.frame_id = frame
        self.publisher = self.create_publisher(type(self.map.to_msg()), topic if topic.startswith("/") else f"/{topic}", MAP_QOS)

    async def on_start(self) -> None:
        self.publisher.publish(self.map.to_msg(self.now().to_msg()))
        self.get_logger().info(f"map {self.map.width}x{self.map.height} at {self.map.resolution} m/cell published on {self.publisher.topic_name}")
