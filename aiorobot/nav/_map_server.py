"""``MapServer``: publishes a map_server YAML map on ``/map`` (transient local), as nav2_map_server.

Its ``~/load_map`` service (nav2_msgs/LoadMap, what BasicNavigator's ``changeMap`` calls) loads
another map and publishes it; a missing file answers RESULT_MAP_DOES_NOT_EXIST, a bad one
RESULT_INVALID_MAP_DATA, each with a warning saying why, and the current map stays.
"""

from __future__ import annotations

from typing import Any

from .._core._node import Node
from .._core._qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from ._maps import MapError, load_map

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
        from aiorobot.msgs.nav2_msgs import LoadMap

        self.create_service(LoadMap, "~/load_map", self._load_map)

    def _load_map(self, request: Any, response: Any) -> Any:
        from pathlib import Path

        url = str(request.map_url)
        try:
            new, document = load_map(url)
        except MapError as err:
            missing = not Path(url).is_file()
            response.result = response.RESULT_MAP_DOES_NOT_EXIST if missing else response.RESULT_INVALID_MAP_DATA
            self.get_logger().warning(f"load_map: {err}; keeping the current map")
            return response
        new.frame_id = self.map.frame_id
        self.map, self.document = new, document
        msg = self.map.to_msg(self.now().to_msg())
        self.publisher.publish(msg)
        response.map, response.result = msg, response.RESULT_SUCCESS
        self.get_logger().info(f"map {url} loaded ({self.map.width}x{self.map.height}) and published")
        return response

    async def on_start(self) -> None:
        self.publisher.publish(self.map.to_msg(self.now().to_msg()))
        self.get_logger().info(f"map {self.map.width}x{self.map.height} at {self.map.resolution} m/cell published on {self.publisher.topic_name}")
