"""A small wall-clock world for nav2_simple_commander-style programs under ``aiorobot exec --node``:
the kinematic robot of test_navigation_e2e at (-1.2, -1.0), test_navigation_e2e's 4 m room (a wall
from x = 0 up to y = 0.8) as a latched /map, and a navigation server."""

from __future__ import annotations

import numpy as np

from aiorobot import Node
from aiorobot.nav import NavigationServer, OccupancyMap
from aiorobot.nav._map_server import MAP_QOS

from .test_navigation_e2e import KinematicRobot


class Robot(KinematicRobot):
    def __init__(self) -> None:
        super().__init__(-1.2, -1.0, 0.0)


class Room(Node):
    """test_navigation_e2e's room, built in memory (0 free, 100 occupied; row 0 at y = -2)."""

    def __init__(self) -> None:
        super().__init__("map_server")
        grid = np.zeros((80, 80), np.int8)
        grid[:2, :] = grid[-2:, :] = grid[:, :2] = grid[:, -2:] = 100
        grid[:56, 39:41] = 100  # rows 0..55 are y < 0.8
        self.map = OccupancyMap(grid, 0.05, (-2.0, -2.0, 0.0))
        self.pub = self.create_publisher(type(self.map.to_msg()), "/map", MAP_QOS)

    async def on_start(self) -> None:
        self.pub.publish(self.map.to_msg(self.now().to_msg()))


class Server(NavigationServer):
    def __init__(self) -> None:
        super().__init__(parameter_overrides={"desired_linear_vel": 0.8})
