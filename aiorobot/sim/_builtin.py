"""The built-in worlds, drawn from rectangles; ``worlds/*.yaml`` + ``*.pgm`` are generated from here.

Regenerate the package files with ``python -m aiorobot.sim._builtin`` (a test checks they match).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ._world import Landmark, World

__all__ = ["CAMERA_HEIGHT_M", "make_box", "make_warehouse", "write_builtin_worlds"]

#: Height of the camera above the floor; markers hang at this height so they face it squarely.
CAMERA_HEIGHT_M = 0.25
_RES = 0.05
_WALL = 0.2
_MARKER = 0.20
_DICT = "DICT_4X4_50"


class _Canvas:
    def __init__(self, x0: float, y0: float, x1: float, y1: float) -> None:
        self.origin = (x0, y0)
        w = round((x1 - x0) / _RES)
        h = round((y1 - y0) / _RES)
        self.grid = np.full((h, w), -1, dtype=np.int8)

    def _index(self, x: float, y: float) -> tuple[int, int]:
        return round((x - self.origin[0]) / _RES), round((y - self.origin[1]) / _RES)

    def fill(self, x0: float, y0: float, x1: float, y1: float, value: int) -> None:
        c0, r0 = self._index(x0, y0)
        c1, r1 = self._index(x1, y1)
        self.grid[r0:r1, c0:c1] = value

    def room(self, x0: float, y0: float, x1: float, y1: float) -> None:
        """Free space inside ``[x0, x1] x [y0, y1]`` with walls of ``_WALL`` outside those faces."""
        self.fill(x0 - _WALL, y0 - _WALL, x1 + _WALL, y1 + _WALL, 100)
        self.fill(x0, y0, x1, y1, 0)

    def world(self, name: str, landmarks: list[Landmark], start: tuple[float, float, float]) -> World:
        return World(name, self.grid, _RES, (self.origin[0], self.origin[1], 0.0), tuple(landmarks), start)


def _marker(marker_id: int, x: float, y: float, facing: float) -> Landmark:
    return Landmark(marker_id, _DICT, _MARKER, x, y, CAMERA_HEIGHT_M, facing)


def make_box() -> World:
    """A closed 6 m x 6 m room: inner wall faces at x = +-3 m and y = +-3 m, markers 0..3 centred on them."""
    canvas = _Canvas(-3.5, -3.5, 3.5, 3.5)
    canvas.room(-3.0, -3.0, 3.0, 3.0)
    landmarks = [
        _marker(0, 3.0, 0.0, math.pi),
        _marker(1, 0.0, 3.0, -0.5 * math.pi),
        _marker(2, -3.0, 0.0, 0.0),
        _marker(3, 0.0, -3.0, 0.5 * math.pi),
    ]
    return canvas.world("box", landmarks, (0.0, 0.0, 0.0))


def make_warehouse() -> World:
    """A 20 m x 14 m warehouse: two rooms west of a dividing wall, a hall with shelf rows east of it.

    Doors (1 m) join the rooms to each other and to the hall; 14 markers hang on the walls.
    """
    canvas = _Canvas(-10.5, -7.5, 10.5, 7.5)
    canvas.room(-10.0, -7.0, 10.0, 7.0)
    # the dividing wall x = -3 with two doors into the hall
    canvas.fill(-3.1, -7.0, -2.9, 7.0, 100)
    canvas.fill(-3.1, -5.5, -2.9, -4.5, 0)
    canvas.fill(-3.1, 3.5, -2.9, 4.5, 0)
    # the wall between the two west rooms (y = 0) with a door
    canvas.fill(-10.0, -0.1, -3.1, 0.1, 100)
    canvas.fill(-7.0, -0.1, -6.0, 0.1, 0)
    # shelf rows in the hall, 0.6 m deep, with 2.9 m corridors between them
    for y in (-3.5, 0.0, 3.5):
        canvas.fill(0.0, y - 0.3, 4.0, y + 0.3, 100)
        canvas.fill(5.5, y - 0.3, 9.0, y + 0.3, 100)
    # pillars
    canvas.fill(-1.2, 1.8, -0.8, 2.2, 100)
    canvas.fill(-1.2, -2.2, -0.8, -1.8, 100)
    # a crate in the north-west room
    canvas.fill(-8.0, 4.0, -7.0, 5.0, 100)
    pi, half = math.pi, 0.5 * math.pi
    landmarks = [
        _marker(0, 10.0, 1.75, pi),
        _marker(1, 10.0, -1.75, pi),
        _marker(2, 10.0, 5.25, pi),
        _marker(3, 10.0, -5.25, pi),
        _marker(4, 6.0, 7.0, -half),
        _marker(5, 0.0, 7.0, -half),
        _marker(6, -6.5, 7.0, -half),
        _marker(7, 6.0, -7.0, half),
        _marker(8, 0.0, -7.0, half),
        _marker(9, -6.5, -7.0, half),
        _marker(10, -10.0, 3.5, 0.0),
        _marker(11, -10.0, -3.5, 0.0),
        _marker(12, -2.9, 0.0, 0.0),
        _marker(13, -3.1, 2.0, pi),
        _marker(14, -3.1, -2.0, pi),
    ]
    return canvas.world("warehouse", landmarks, (-8.0, -5.0, 0.0))


def write_builtin_worlds(directory: Path | None = None) -> list[Path]:
    """Write every built-in world's YAML + PGM into ``directory`` (the package's ``worlds/``)."""
    from ._world_file import save_world

    target = directory or Path(__file__).parent / "worlds"
    return [save_world(make(), target / f"{make().name}.yaml") for make in (make_box, make_warehouse)]


if __name__ == "__main__":
    for written in write_builtin_worlds():
        print(written)
