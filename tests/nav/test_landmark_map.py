"""The landmark map nav owns: its file format, its loader's one-line errors, and nav's independence of the simulator."""

from __future__ import annotations

import ast
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from aiorobot.nav import (
    LandmarkFixNode,
    LandmarkMap,
    LandmarkMapError,
    MarkerPlace,
    landmark_map_path,
    load_landmark_map,
    map_from_marker,
    save_landmark_map,
)

NAV = Path(__file__).resolve().parents[2] / "aiorobot" / "nav"


def test_a_saved_map_loads_back_with_every_marker_and_its_pose(tmp_path: Path) -> None:
    places = [MarkerPlace(7, 0.15, 1.0, -2.0, 0.3, math.pi / 2, "DICT_5X5_100"), MarkerPlace(2, 0.2, 0.0, 3.0, 0.25, 0.0)]
    path = save_landmark_map(places, tmp_path / "site.landmarks.yaml")
    loaded = load_landmark_map(path)
    assert list(loaded.markers) == [2, 7] and loaded.frame_id == "map" and loaded.path == str(path)
    assert loaded.markers[7] == places[0] and loaded.markers[2] == places[1]
    np.testing.assert_array_equal(loaded.markers[7].map_from_marker(), map_from_marker(1.0, -2.0, 0.3, math.pi / 2))


def test_the_map_lies_beside_the_map_yaml() -> None:
    assert landmark_map_path("maps/box.yaml") == Path("maps/box.landmarks.yaml")
    assert landmark_map_path(Path("/srv/site.yml")) == Path("/srv/site.landmarks.yaml")


def test_a_hand_written_map_takes_the_default_dictionary_and_frame(tmp_path: Path) -> None:
    path = tmp_path / "m.landmarks.yaml"
    path.write_text("markers:\n  4: {size: 0.2, pose: [1, 2, 0.25, 3.14]}\n")
    (m,) = load_landmark_map(path).markers.values()
    assert (m.id, m.dictionary, m.size, m.x, m.y, m.z, m.yaw) == (4, "DICT_4X4_50", 0.2, 1.0, 2.0, 0.25, 3.14)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("markers:\n  0: {size: 0.2, pose: [1, 2, 3]}\n",
         r"markers\.0\.pose: expected \[x, y, z, yaw\] \(4 numbers\), found \[1, 2, 3\]"),
        ("markers:\n  a: {size: 0.2, pose: [1, 2, 3, 0]}\n",
         r"markers\.a: expected an ArUco id \(an integer >= 0\) as the key, found 'a'"),
        ("markers:\n  1: {pose: [1, 2, 3, 0]}\n", r"markers\.1\.size: missing; a marker needs size"),
        ("markers:\n  1: {size: -1, pose: [1, 2, 3, 0]}\n", r"markers\.1\.size: expected a side length > 0 m, found -1"),
        ("markers:\n  1: {size: 0.2, pose: [1, .nan, 3, 0]}\n", r"markers\.1\.pose\[1\]: expected a finite number, found nan"),
        ("markers:\n  1: {size: 0.2, pose: [1, 2, 3, 0], dictionary: aruco}\n",
         r"markers\.1\.dictionary: expected an OpenCV ArUco dictionary name such as DICT_4X4_50, found 'aruco'"),
        ("markers:\n  1: {size: 0.2, pose: [1, 2, 3, 0], colour: red}\n",
         r"markers\.1\.colour: unknown key; a marker has dictionary, size and pose"),
        ("landmarks: []\n", r"landmarks: unknown key; a landmark map has frame_id and markers"),
        ("frame_id: map\n", r"markers: expected a mapping of ArUco id -> \{size, pose\}, found None"),
        ("markers: [\n", r"not valid YAML at line 2"),
    ],
)
def test_a_bad_file_gets_one_line_naming_the_file_and_the_key(tmp_path: Path, text: str, message: str) -> None:
    path = tmp_path / "bad.landmarks.yaml"
    path.write_text(text)
    with pytest.raises(LandmarkMapError, match=rf"^{path}: {message}") as err:
        load_landmark_map(path)
    assert "\n" not in str(err.value)


def test_a_missing_file_says_how_to_make_one(tmp_path: Path) -> None:
    with pytest.raises(LandmarkMapError, match=r"nope\.landmarks\.yaml: landmark map not found; write one beside the map"):
        load_landmark_map(tmp_path / "nope.landmarks.yaml")


def test_a_repeated_id_is_refused() -> None:
    with pytest.raises(LandmarkMapError, match=r"markers: id 3 appears twice"):
        LandmarkMap.from_markers([MarkerPlace(3, 0.2, 0, 0, 0, 0), MarkerPlace(3, 0.2, 1, 0, 0, 0)])


def test_the_fix_node_reads_its_map_and_refuses_none_or_another_frame(tmp_path: Path) -> None:
    path = save_landmark_map([MarkerPlace(1, 0.2, 3.0, 0.0, 0.25, math.pi)], tmp_path / "a.landmarks.yaml")
    node = LandmarkFixNode(parameter_overrides={"landmark_map": str(path)})
    assert list(node.landmarks) == [1] and node.landmark_map.markers[1].x == 3.0
    with pytest.raises(ValueError, match=r"^parameter landmark_map: expected the path of a landmark map file"):
        LandmarkFixNode()
    with pytest.raises(ValueError, match=rf"^{path}: frame_id: expected the map frame 'world' \(parameter map_frame\), found 'map'$"):
        LandmarkFixNode(parameter_overrides={"landmark_map": str(path), "map_frame": "world"})


def test_no_nav_module_imports_the_simulator() -> None:
    for source in sorted(NAV.glob("*.py")):
        for node in ast.walk(ast.parse(source.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom):
                names = [("." * node.level) + (node.module or "")]
            elif isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            else:
                continue
            for name in names:
                assert not (name.startswith("aiorobot.sim") or name.startswith("..sim")), f"{source.name} imports {name}"


def test_a_fix_node_on_a_landmark_map_loads_no_simulator(tmp_path: Path) -> None:
    path = save_landmark_map([MarkerPlace(0, 0.2, 1.0, 0.0, 0.25, math.pi)], tmp_path / "a.landmarks.yaml")
    code = ("import sys\nfrom aiorobot.nav import LandmarkFixNode\n"
            f"LandmarkFixNode(parameter_overrides={{'landmark_map': {str(path)!r}}})\n"
            "print(sorted(m for m in sys.modules if m.startswith('aiorobot.sim')))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=50, check=True)
    assert out.stdout.strip() == "[]"
