"""The simulator's worlds export navigation's landmark map beside their map YAML."""

from __future__ import annotations

from pathlib import Path

import pytest

from aiorobot.nav import landmark_map_path, load_landmark_map
from aiorobot.sim import BUILTIN_WORLDS, World, builtin_world_path, make_box, make_warehouse, save_world


def _same_places(world: World, path: Path) -> None:
    markers = load_landmark_map(path).markers
    assert sorted(markers) == sorted(lm.id for lm in world.landmarks)
    for lm in world.landmarks:
        m = markers[lm.id]
        assert (m.size, m.x, m.y, m.z, m.yaw, m.dictionary) == (lm.size, lm.x, lm.y, lm.z, lm.yaw, lm.dictionary)


def test_save_world_writes_the_landmark_map_beside_the_map(tmp_path: Path) -> None:
    world = make_box()
    yaml_path = save_world(world, tmp_path / "room.yaml")
    assert (tmp_path / "room.landmarks.yaml").is_file()
    _same_places(world, landmark_map_path(yaml_path))


@pytest.mark.parametrize("make", [make_box, make_warehouse])
def test_each_built_in_world_ships_its_landmark_map_matching_the_generator(make) -> None:
    built = make()
    assert built.name in BUILTIN_WORLDS
    _same_places(built, landmark_map_path(builtin_world_path(built.name)))

