"""Reading and writing world files (map_server YAML + image, plus ``landmarks`` and ``start``)."""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any

import numpy as np

from ._world import Landmark, World, WorldError, _landmark_dict

__all__ = ["export_landmark_map", "load_world", "save_world"]

_MODES = ("trinary",)


def _fail(path: Path, key: str, message: str) -> WorldError:
    where = f"{path}: {key}: " if key else f"{path}: "
    return WorldError(where + message)


def _number(path: Path, key: str, value: Any, *, low: float | None = None, high: float | None = None,
            low_open: bool = False) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise _fail(path, key, f"expected a finite number, found {value!r}")
    v = float(value)
    if low is not None and (v <= low if low_open else v < low):
        raise _fail(path, key, f"expected a number {'>' if low_open else '>='} {low:g}, found {value!r}")
    if high is not None and v > high:
        raise _fail(path, key, f"expected a number <= {high:g}, found {value!r}")
    return v


def _vector(path: Path, key: str, value: Any, n: int) -> tuple[float, ...]:
    if not isinstance(value, (list, tuple)) or len(value) != n:
        raise _fail(path, key, f"expected a list of {n} numbers, found {value!r}")
    return tuple(_number(path, f"{key}[{i}]", v) for i, v in enumerate(value))


def load_world(path: Path, *, name: str | None = None) -> World:
    """Parse and check a world YAML and its image; :class:`WorldError` on any problem."""
    import yaml

    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise WorldError(f"{path}: world file not found; give a built-in name (box, warehouse) or a map YAML path") from None
    except (OSError, UnicodeDecodeError) as err:
        raise WorldError(f"{path}: cannot read the world file ({err})") from None
    try:
        data = yaml.safe_load(text)
    except yaml.YAMLError as err:
        mark = getattr(err, "problem_mark", None)
        where = f" at line {mark.line + 1}" if mark is not None else ""
        raise WorldError(f"{path}: not valid YAML{where}: {getattr(err, 'problem', err)}") from None
    if not isinstance(data, dict):
        raise _fail(path, "", f"expected a map_server YAML mapping (image, resolution, origin, ...), found {type(data).__name__}")
    for key in ("image", "resolution", "origin"):
        if key not in data:
            raise _fail(path, key, "missing; a map_server YAML needs image, resolution and origin")
    image_name = data["image"]
    if not isinstance(image_name, str) or not image_name:
        raise _fail(path, "image", f"expected an image file name (PGM or PNG), found {image_name!r}")
    resolution = _number(path, "resolution", data["resolution"], low=0.0, low_open=True)
    origin = _vector(path, "origin", data["origin"], 3)
    if origin[2] != 0.0:
        raise _fail(path, "origin", f"a rotated map (yaw {origin[2]!r}) is not supported; set the yaw to 0")
    occupied_thresh = _number(path, "occupied_thresh", data.get("occupied_thresh", 0.65), low=0.0, high=1.0)
    free_thresh = _number(path, "free_thresh", data.get("free_thresh", 0.196), low=0.0, high=1.0)
    if free_thresh > occupied_thresh:
        raise _fail(path, "free_thresh", f"expected <= occupied_thresh ({occupied_thresh:g}), found {free_thresh:g}")
    negate = data.get("negate", 0)
    if negate not in (0, 1) or isinstance(negate, float):
        raise _fail(path, "negate", f"expected 0 or 1, found {negate!r}")
    mode = data.get("mode", "trinary")
    if mode not in _MODES:
        raise _fail(path, "mode", f"expected 'trinary' (the only mode the simulator reads), found {mode!r}")

    image_path = Path(image_name) if os.path.isabs(image_name) else path.parent / image_name
    occupancy = _read_image(path, image_path, occupied_thresh, free_thresh, bool(negate))
    h, w = occupancy.shape
    world_w, world_h = w * resolution, h * resolution

    landmarks = []
    raw_landmarks = data.get("landmarks", []) or []
    if not isinstance(raw_landmarks, list):
        raise _fail(path, "landmarks", f"expected a list of markers, found {raw_landmarks!r}")
    seen: set[int] = set()
    for i, raw in enumerate(raw_landmarks):
        key = f"landmarks[{i}]"
        if not isinstance(raw, dict):
            raise _fail(path, key, f"expected a mapping with id, dictionary, size, pose; found {raw!r}")
        for required in ("id", "size", "pose"):
            if required not in raw:
                raise _fail(path, f"{key}.{required}", "missing; a landmark needs id, size (m) and pose [x, y, z, yaw]")
        marker_id = raw["id"]
        if isinstance(marker_id, bool) or not isinstance(marker_id, int) or marker_id < 0:
            raise _fail(path, f"{key}.id", f"expected an ArUco id >= 0, found {marker_id!r}")
        if marker_id in seen:
            raise _fail(path, f"{key}.id", f"id {marker_id} appears twice; every landmark needs its own id")
        seen.add(marker_id)
        dictionary = raw.get("dictionary", "DICT_4X4_50")
        _check_dictionary(path, f"{key}.dictionary", dictionary, marker_id)
        size = _number(path, f"{key}.size", raw["size"], low=0.0, low_open=True)
        x, y, z, yaw = _vector(path, f"{key}.pose", raw["pose"], 4)
        ox, oy = origin[0], origin[1]
        if not (ox <= x <= ox + world_w and oy <= y <= oy + world_h):
            raise _fail(
                path, f"{key}.pose",
                f"landmark {marker_id} at ({x:g}, {y:g}) is outside the map "
                f"(x {ox:g}..{ox + world_w:g}, y {oy:g}..{oy + world_h:g}); move it onto the map",
            )
        landmarks.append(Landmark(int(marker_id), str(dictionary), size, x, y, z, yaw))
    start = _vector(path, "start", data.get("start", [0.0, 0.0, 0.0]), 3)
    world = World(
        name=name or path.stem,
        occupancy=occupancy,
        resolution=resolution,
        origin=(origin[0], origin[1], origin[2]),
        landmarks=tuple(landmarks),
        start=(start[0], start[1], start[2]),
        path=str(path),
    )
    if not world.contains(start[0], start[1]):
        raise _fail(path, "start", f"start ({start[0]:g}, {start[1]:g}) is outside the map; move it onto the map")
    return world


def _check_dictionary(path: Path, key: str, dictionary: Any, marker_id: int) -> None:
    import cv2

    if not isinstance(dictionary, str) or not dictionary.startswith("DICT_") or not hasattr(cv2.aruco, dictionary):
        raise _fail(path, key, f"expected an OpenCV ArUco dictionary name such as DICT_4X4_50, found {dictionary!r}")
    size = cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, dictionary)).bytesList.shape[0]
    if marker_id >= size:
        raise _fail(path, key, f"{dictionary} has ids 0..{size - 1}, found id {marker_id}; pick a larger dictionary")


def _read_image(yaml_path: Path, image_path: Path, occupied_thresh: float, free_thresh: float, negate: bool) -> np.ndarray:
    import cv2

    if not image_path.is_file():
        raise _fail(yaml_path, "image", f"image file {image_path} not found; put the PGM/PNG next to the YAML")
    raw = cv2.imread(str(image_path), cv2.IMREAD_UNCHANGED)
    if raw is None or raw.size == 0:
        raise _fail(yaml_path, "image", f"{image_path} is not a readable image; expected a grayscale PGM or PNG map")
    if raw.ndim == 3:
        raw = raw[..., :3].mean(axis=2)  # map_server averages the colour channels
    if raw.dtype == np.uint16:
        raw = raw / 257.0
    elif raw.dtype != np.uint8 and not np.issubdtype(raw.dtype, np.floating):
        raise _fail(yaml_path, "image", f"{image_path} has pixel type {raw.dtype}; expected 8-bit grayscale")
    value = np.asarray(raw, dtype=np.float64)
    p = value / 255.0 if negate else (255.0 - value) / 255.0
    occupancy = np.full(value.shape, -1, dtype=np.int8)
    occupancy[p > occupied_thresh] = 100
    occupancy[p < free_thresh] = 0
    return np.ascontiguousarray(occupancy[::-1])


def save_world(world: World, yaml_path: str | os.PathLike[str]) -> Path:
    """Write ``world`` as ``<name>.yaml`` + ``<name>.pgm`` (map_server format plus landmarks) and
    navigation's landmark map beside them, ``<name>.landmarks.yaml`` (:func:`export_landmark_map`)."""
    import cv2
    import yaml

    yaml_path = Path(yaml_path)
    image_path = yaml_path.with_suffix(".pgm")
    if not cv2.imwrite(str(image_path), world.to_image()):
        raise OSError(f"could not write {image_path}")
    data = {
        "image": image_path.name,
        "mode": "trinary",
        "resolution": world.resolution,
        "origin": list(world.origin),
        "negate": 0,
        "occupied_thresh": 0.65,
        "free_thresh": 0.196,
        "start": list(world.start),
        "landmarks": [_landmark_dict(lm) for lm in world.landmarks],
    }
    yaml_path.write_text(yaml.safe_dump(data, sort_keys=False, default_flow_style=None), encoding="utf-8")
    export_landmark_map(world, yaml_path)
    return yaml_path


def export_landmark_map(world: World, map_yaml: str | os.PathLike[str]) -> Path:
    """Write the world's landmarks as navigation's landmark map beside ``map_yaml``
    (:func:`aiorobot.nav.landmark_map_path`; the format is :mod:`aiorobot.nav`'s, which never reads a world)."""
    from aiorobot.nav import MarkerPlace, landmark_map_path, save_landmark_map

    places = [MarkerPlace(lm.id, lm.size, lm.x, lm.y, lm.z, lm.yaw, lm.dictionary) for lm in world.landmarks]
    return save_landmark_map(places, landmark_map_path(map_yaml))
