"""Worlds: built-ins, map_server parsing, and one clear error per bad input."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from aiorobot.sim import BUILTIN_WORLDS, World, WorldError, make_box, make_warehouse, raycast, save_world


def test_box_has_inner_wall_faces_at_three_metres() -> None:
    world = World.load("box")
    assert world.start == (0.0, 0.0, 0.0)
    assert world.resolution == 0.05
    for x, y in [(2.99, 0.0), (-2.99, 0.0), (0.0, 2.99), (0.0, -2.99)]:
        row, col = world.cell(x, y)
        assert world.occupancy[row, col] == 0
    for x, y in [(3.01, 0.0), (-3.01, 0.0), (0.0, 3.01), (0.0, -3.01)]:
        row, col = world.cell(x, y)
        assert world.occupancy[row, col] == 100


def test_box_markers_are_centred_on_the_walls_facing_the_room() -> None:
    world = World.load("box")
    expected = {0: (3.0, 0.0, math.pi), 1: (0.0, 3.0, -math.pi / 2), 2: (-3.0, 0.0, 0.0), 3: (0.0, -3.0, math.pi / 2)}
    assert sorted(lm.id for lm in world.landmarks) == [0, 1, 2, 3]
    for lm in world.landmarks:
        x, y, yaw = expected[lm.id]
        assert (lm.x, lm.y) == pytest.approx((x, y))
        assert math.cos(lm.yaw - yaw) == pytest.approx(1.0)
        assert lm.dictionary == "DICT_4X4_50" and lm.size == pytest.approx(0.20)
        # facing the room: the normal points back to the centre
        assert math.cos(lm.yaw) * -lm.x + math.sin(lm.yaw) * -lm.y > 0


def test_warehouse_landmarks_sit_on_wall_faces_in_view_of_free_space() -> None:
    world = World.load("warehouse")
    assert len(world.landmarks) >= 12
    assert world.width_m >= 20 and world.is_free_disc(*world.start[:2], 0.25)
    for lm in world.landmarks:
        # a point 1 m in front of the marker is free and a ray back hits the marker's wall right at it
        fx, fy = lm.x + math.cos(lm.yaw), lm.y + math.sin(lm.yaw)
        assert world.is_free_disc(fx, fy, 0.2), lm
        hit = raycast(world.occupied, world.resolution, world.origin[:2], (fx, fy), np.array([lm.yaw + math.pi]))[0]
        assert hit == pytest.approx(1.0, abs=world.resolution), lm


def test_built_in_files_match_their_generator(tmp_path: Path) -> None:
    for make in (make_box, make_warehouse):
        built = make()
        assert built.name in BUILTIN_WORLDS
        packaged = World.load(built.name)
        np.testing.assert_array_equal(packaged.occupancy, built.occupancy)
        assert packaged.landmarks == built.landmarks and packaged.start == built.start


def test_save_and_load_round_trip(tmp_path: Path) -> None:
    world = make_box()
    path = save_world(world, tmp_path / "room.yaml")
    again = World.load(path)
    np.testing.assert_array_equal(again.occupancy, world.occupancy)
    assert again.origin == world.origin and again.landmarks == world.landmarks


def _write(tmp_path: Path, yaml_text: str, image: bytes | None = None) -> Path:
    if image is None:
        world = make_box()
        save_world(world, tmp_path / "base.yaml")
        (tmp_path / "map.pgm").write_bytes((tmp_path / "base.pgm").read_bytes())
    else:
        (tmp_path / "map.pgm").write_bytes(image)
    path = tmp_path / "world.yaml"
    path.write_text(yaml_text)
    return path


GOOD = "image: map.pgm\nresolution: 0.05\norigin: [-3.5, -3.5, 0.0]\n"


def test_map_server_thresholds_and_negate(tmp_path: Path) -> None:
    image = b"P5\n3 1\n255\n" + bytes([0, 128, 255])
    small = "image: map.pgm\nresolution: 0.05\norigin: [0.0, 0.0, 0.0]\n"
    path = _write(tmp_path, small + "occupied_thresh: 0.65\nfree_thresh: 0.196\nnegate: 0\n", image)
    assert World.load(path).occupancy.tolist() == [[100, -1, 0]]
    path.write_text(small + "negate: 1\n")
    assert World.load(path).occupancy.tolist() == [[0, -1, 100]]


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("image: map.pgm\norigin: [0, 0, 0]\n", r"world\.yaml: resolution: missing"),
        (GOOD.replace("0.05", "-0.05"), r"resolution: expected a number > 0, found -0\.05"),
        (GOOD + "negate: 2\n", r"negate: expected 0 or 1, found 2"),
        (GOOD + "mode: scale\n", r"mode: expected 'trinary'"),
        (GOOD + "free_thresh: 0.9\n", r"free_thresh: expected <= occupied_thresh"),
        ("image: [unclosed\n", r"not valid YAML at line"),
        (GOOD + "landmarks:\n  - {id: 5, size: 0.2, pose: [40.0, 0.0, 0.25, 0.0]}\n",
         r"landmarks\[0\]\.pose: landmark 5 at \(40, 0\) is outside the map .*move it onto the map"),
        (GOOD + "landmarks:\n  - {id: 5, dictionary: DICT_NOPE, size: 0.2, pose: [0, 0, 0.25, 0]}\n",
         r"landmarks\[0\]\.dictionary: expected an OpenCV ArUco dictionary name"),
        (GOOD + "landmarks:\n  - {id: 60, size: 0.2, pose: [0, 0, 0.25, 0]}\n", r"DICT_4X4_50 has ids 0\.\.49, found id 60"),
        (GOOD + "landmarks:\n  - {id: 1, size: -0.2, pose: [0, 0, 0.25, 0]}\n", r"landmarks\[0\]\.size: expected a number > 0"),
        (GOOD.replace("map.pgm", "missing.pgm"), r"image: image file .*missing\.pgm not found"),
    ],
)
def test_bad_world_files_name_the_file_and_key(tmp_path: Path, text: str, message: str) -> None:
    path = _write(tmp_path, text)
    with pytest.raises(WorldError, match=message) as info:
        World.load(path)
    assert str(path) in str(info.value)


def test_an_image_that_is_not_a_map_is_refused(tmp_path: Path) -> None:
    path = _write(tmp_path, GOOD, image=b"this is not an image at all")
    with pytest.raises(WorldError, match=r"map\.pgm is not a readable image; expected a grayscale PGM or PNG map"):
        World.load(path)


def test_missing_world_and_unknown_name(tmp_path: Path) -> None:
    with pytest.raises(WorldError, match=r"nothere\.yaml: world file not found"):
        World.load(tmp_path / "nothere.yaml")
    with pytest.raises(WorldError, match=r"expected a built-in name \(box, warehouse\) or a path"):
        World.load("boxx")
