"""map_server YAML + image: loading rules, round trip through save, OccupancyGrid conversion, bad files."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import pytest

from aiorobot.nav._maps import MapError, OccupancyMap, load_map, save_map


def _write(tmp: Path, pixels: np.ndarray, **yaml: object) -> Path:
    cv2.imwrite(str(tmp / "m.pgm"), pixels)
    doc = {"image": "m.pgm", "resolution": 0.1, "origin": [-1.0, -2.0, 0.0], "occupied_thresh": 0.65, "free_thresh": 0.196, "negate": 0, **yaml}
    text = "\n".join(f"{k}: {v!r}" if not isinstance(v, list) else f"{k}: {v}" for k, v in doc.items())
    (tmp / "m.yaml").write_text(text.replace("'", ""))
    return tmp / "m.yaml"


def test_trinary_loading_follows_map_server_and_flips_rows(tmp_path: Path) -> None:
    pixels = np.array([[0, 254], [205, 128]], dtype=np.uint8)  # top row first in the image
    m, _ = load_map(_write(tmp_path, pixels))
    # image top row (0 black = occupied, 254 white = free) becomes the grid's last row
    assert m.data.tolist() == [[-1, -1], [100, 0]]
    assert m.resolution == 0.1 and m.origin == (-1.0, -2.0, 0.0)
    neg, _ = load_map(_write(tmp_path, pixels, negate=1))
    assert neg.data.tolist() == [[100, -1], [0, 100]]


def test_save_then_load_gives_the_same_grid(tmp_path: Path) -> None:
    rng = np.random.default_rng(0)
    data = rng.choice(np.array([-1, 0, 100], dtype=np.int8), size=(30, 40))
    m = OccupancyMap(data, 0.05, (1.0, 2.0, 0.0))
    yaml_path = save_map(m, tmp_path / "saved")
    back, doc = load_map(yaml_path)
    assert np.array_equal(back.data, data)
    assert doc["image"] == "saved.pgm" and back.origin == (1.0, 2.0, 0.0)


def test_occupancy_grid_message_round_trip() -> None:
    m = OccupancyMap(np.arange(12, dtype=np.int8).reshape(3, 4), 0.2, (0.5, -0.5, 0.3))
    back = OccupancyMap.from_msg(m.to_msg())
    assert np.array_equal(back.data, m.data) and back.origin == pytest.approx(m.origin)


def test_bad_map_files_name_the_file_and_the_problem(tmp_path: Path) -> None:
    with pytest.raises(MapError, match="no such map file"):
        load_map(tmp_path / "nope.yaml")
    (tmp_path / "a.yaml").write_text("image: m.pgm\nresolution: 0.05\n")
    with pytest.raises(MapError, match=r"a.yaml: missing key 'origin'"):
        load_map(tmp_path / "a.yaml")
    (tmp_path / "b.yaml").write_text("image: missing.pgm\nresolution: 0.05\norigin: [0, 0, 0]\n")
    with pytest.raises(MapError, match=r"image 'missing.pgm' does not exist"):
        load_map(tmp_path / "b.yaml")
    (tmp_path / "notimage.pgm").write_text("hello")
    (tmp_path / "c.yaml").write_text("image: notimage.pgm\nresolution: 0.05\norigin: [0, 0, 0]\n")
    with pytest.raises(MapError, match="cannot be read as an image"):
        load_map(tmp_path / "c.yaml")
    (tmp_path / "d.yaml").write_text("image: notimage.pgm\nresolution: -1\norigin: [0, 0, 0]\n")
    with pytest.raises(MapError, match="resolution must be > 0"):
        load_map(tmp_path / "d.yaml")
