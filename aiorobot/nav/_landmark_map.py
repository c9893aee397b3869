"""The landmark map: where each ArUco marker hangs in the map frame, in a YAML file beside the map.

Navigation owns this file (the simulator's worlds export it: :func:`aiorobot.sim.save_world`
writes ``<map>.landmarks.yaml`` beside ``<map>.yaml``); :class:`~aiorobot.nav.LandmarkFixNode`
reads it. The format::

    # aiorobot landmark map
    frame_id: map                # the frame the poses are in (default map)
    markers:                     # ArUco id -> where the marker is
      0: {dictionary: DICT_4X4_50, size: 0.2, pose: [3.0, 0.0, 0.25, 3.141593]}
      1: {size: 0.2, pose: [0.0, 3.0, 0.25, -1.570796]}

``size`` is the black square's side (m); ``pose`` is ``[x, y, z, yaw]`` of the square's centre,
``yaw`` the direction of the marker's outward normal (the way a camera must look *against* to see
it); ``dictionary`` (default DICT_4X4_50) is the OpenCV ArUco dictionary the id belongs to.

This module is pure (PyYAML and numbers); :class:`LandmarkMapError` names the file and the key.
"""

from __future__ import annotations

import math
import os
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = [
    "LANDMARK_MAP_SUFFIX",
    "LandmarkMap",
    "LandmarkMapError",
    "MarkerPlace",
    "landmark_map_path",
    "load_landmark_map",
    "save_landmark_map",
]

#: What replaces a map YAML's ``.yaml`` in the name of the landmark map beside it.
LANDMARK_MAP_SUFFIX = ".landmarks.yaml"
_DEFAULT_DICTIONARY = "DICT_4X4_50"
_MARKER_KEYS = ("dictionary", "size", "pose")


class LandmarkMapError(ValueError):
    """A landmark map file that cannot be used: ``<file>: <key>: expected ..., found ...`` on one line."""


@dataclass(frozen=True, slots=True)
class MarkerPlace:
    """One marker of a landmark map: ``size`` m square centred at ``(x, y, z)``, its face looking along ``yaw``."""

    id: int
    size: float
    x: float
    y: float
    z: float
    yaw: float
    dictionary: str = _DEFAULT_DICTIONARY

    def map_from_marker(self) -> NDArray[np.float64]:
        """The (4, 4) pose of the marker's ArUco frame in the map (:func:`aiorobot.nav.map_from_marker`)."""
        from ._landmarks import map_from_marker

        return map_from_marker(self.x, self.y, self.z, self.yaw)


@dataclass(frozen=True, slots=True)
class LandmarkMap:
    """A loaded landmark map: ``markers`` by ArUco id, poses in ``frame_id``."""

    markers: Mapping[int, MarkerPlace] = field(default_factory=lambda: MappingProxyType({}))
    frame_id: str = "map"
    path: str = ""

    def __repr__(self) -> str:
        return f"<LandmarkMap {self.path or '(not from a file)'} markers={sorted(self.markers)} in {self.frame_id}>"

    @classmethod
    def from_markers(cls, markers: Iterable[MarkerPlace], frame_id: str = "map", path: str = "") -> LandmarkMap:
        by_id: dict[int, MarkerPlace] = {}
        for m in markers:
            if m.id in by_id:
                raise LandmarkMapError(f"{path or 'landmark map'}: markers: id {m.id} appears twice; "
                                       "every marker needs its own id")
            by_id[m.id] = m
        return cls(MappingProxyType(dict(sorted(by_id.items()))), frame_id, path)


def landmark_map_path(map_yaml: str | os.PathLike[str]) -> Path:
    """The landmark map beside a map YAML: ``maps/box.yaml`` -> ``maps/box.landmarks.yaml``."""
    path = Path(map_yaml)
    stem = path.name[: -len(path.suffix)] if path.suffix in (".yaml", ".yml") else path.name
    return path.with_name(stem + LANDMARK_MAP_SUFFIX)


def _fail(path: str, key: str, message: str) -> LandmarkMapError:
    return LandmarkMapError(f"{path}: {key}: {message}" if key else f"{path}: {message}")


def _number(path: str, key: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise _fail(path, key, f"expected a finite number, found {value!r}")
    return float(value)


def load_landmark_map(path: str | os.PathLike[str]) -> LandmarkMap:
    """Read and check a landmark map file; :class:`LandmarkMapError` (one line, file and key) on any problem."""
    import yaml

    name = os.fspath(path)
    try:
        text = Path(name).read_text(encoding="utf-8")
    except FileNotFoundError:
        raise _fail(name, "", "landmark map not found; write one beside the map (aiorobot.sim.save_world "
                              "exports it for a simulator world)") from None
    except (OSError, UnicodeDecodeError) as err:
        raise _fail(name, "", f"cannot read the landmark map ({err})") from None
    try:
        data = yaml.safe_load(text)
    except yaml.YAMLError as err:
        mark = getattr(err, "problem_mark", None)
        where = f" at line {mark.line + 1}" if mark is not None else ""
        raise _fail(name, "", f"not valid YAML{where}: {getattr(err, 'problem', err)}") from None
    if not isinstance(data, dict):
        raise _fail(name, "", f"expected a mapping with frame_id and markers, found {type(data).__name__}")
    unknown = sorted(str(k) for k in data if k not in ("frame_id", "markers"))
    if unknown:
        raise _fail(name, unknown[0], "unknown key; a landmark map has frame_id and markers")
    frame_id = data.get("frame_id", "map")
    if not isinstance(frame_id, str) or not frame_id:
        raise _fail(name, "frame_id", f"expected a frame name such as map, found {frame_id!r}")
    raw = data.get("markers")
    if not isinstance(raw, dict):
        raise _fail(name, "markers", f"expected a mapping of ArUco id -> {{size, pose}}, found {raw!r}")
    markers = []
    for marker_id, entry in raw.items():
        key = f"markers.{marker_id}"
        if isinstance(marker_id, bool) or not isinstance(marker_id, int) or marker_id < 0:
            raise _fail(name, key, f"expected an ArUco id (an integer >= 0) as the key, found {marker_id!r}")
        if not isinstance(entry, dict):
            raise _fail(name, key, f"expected a mapping with size and pose, found {entry!r}")
        extra = sorted(str(k) for k in entry if k not in _MARKER_KEYS)
        if extra:
            raise _fail(name, f"{key}.{extra[0]}", "unknown key; a marker has dictionary, size and pose")
        for required in ("size", "pose"):
            if required not in entry:
                raise _fail(name, f"{key}.{required}", "missing; a marker needs size (m) and pose [x, y, z, yaw]")
        size = _number(name, f"{key}.size", entry["size"])
        if size <= 0.0:
            raise _fail(name, f"{key}.size", f"expected a side length > 0 m, found {entry['size']!r}")
        pose = entry["pose"]
        if not isinstance(pose, list) or len(pose) != 4:
            raise _fail(name, f"{key}.pose", f"expected [x, y, z, yaw] (4 numbers), found {pose!r}")
        x, y, z, yaw = (_number(name, f"{key}.pose[{i}]", v) for i, v in enumerate(pose))
        dictionary = entry.get("dictionary", _DEFAULT_DICTIONARY)
        if not isinstance(dictionary, str) or not dictionary.startswith("DICT_"):
            raise _fail(name, f"{key}.dictionary", f"expected an OpenCV ArUco dictionary name such as "
                                                   f"DICT_4X4_50, found {dictionary!r}")
        markers.append(MarkerPlace(marker_id, size, x, y, z, yaw, dictionary))
    return LandmarkMap.from_markers(markers, frame_id, name)


def save_landmark_map(landmarks: LandmarkMap | Iterable[MarkerPlace], path: str | os.PathLike[str]) -> Path:
    """Write a landmark map file (the format in this module's docstring); returns its path."""
    import yaml

    lm = landmarks if isinstance(landmarks, LandmarkMap) else LandmarkMap.from_markers(landmarks)
    data = {
        "frame_id": lm.frame_id,
        "markers": {m.id: {"dictionary": m.dictionary, "size": m.size, "pose": [m.x, m.y, m.z, m.yaw]}
                    for m in lm.markers.values()},
    }
    target = Path(path)
    header = "# aiorobot landmark map: ArUco id -> size (m) and pose [x, y, z, yaw] in frame_id (aiorobot.nav)\n"
    target.write_text(header + yaml.safe_dump(data, sort_keys=False, default_flow_style=None), encoding="utf-8")
    return target
