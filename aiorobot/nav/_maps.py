"""Occupancy maps in ROS map_server's format (YAML + PGM/PNG), to and from nav_msgs/OccupancyGrid.

Loading follows nav2_map_server (``mode: trinary``, the default): a pixel's occupancy
probability is ``(255 - v) / 255`` (``v / 255`` with ``negate: 1``); above ``occupied_thresh``
-> 100, below ``free_thresh`` -> 0, else -1 (unknown). ``mode: scale`` keeps the probability as
0..100 in between; ``mode: raw`` takes pixel values as they are. Image row 0 is the top of the map
(the largest y), so rows are flipped into the grid's row 0 = ``origin`` layout. Saving writes what
map_saver writes: occupied 0 (black), free 254, unknown 205, with thresholds 0.65 / 0.196 (the
value for which unknown pixels load back as unknown).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = ["MapError", "OccupancyMap", "load_map", "save_map"]


class MapError(Exception):
    """A map file that cannot be used; the message names the file, the key and what was expected."""


@dataclass
class OccupancyMap:
    """``data`` (H, W) int8 in OccupancyGrid values (-1, 0..100), row 0 at ``origin``'s y."""

    data: NDArray[np.int8]
    resolution: float
    origin: tuple[float, float, float]  # x, y, yaw
    frame_id: str = "map"

    @property
    def height(self) -> int:
        return int(self.data.shape[0])

    @property
    def width(self) -> int:
        return int(self.data.shape[1])

    @property
    def occupied(self) -> NDArray[np.bool_]:
        return self.data >= 65

    def to_msg(self, stamp: Any = None) -> Any:
        from aiorobot.msgs.nav_msgs import MapMetaData, OccupancyGrid
        from aiorobot.msgs.geometry_msgs import Point, Pose, Quaternion
        from aiorobot.msgs.std_msgs import Header

        yaw = self.origin[2]
        msg = OccupancyGrid(
            header=Header(frame_id=self.frame_id),
            info=MapMetaData(
                resolution=float(self.resolution),
                width=self.width,
                height=self.height,
                origin=Pose(position=Point(x=float(self.origin[0]), y=float(self.origin[1])),
                            orientation=Quaternion(z=math.sin(yaw / 2), w=math.cos(yaw / 2))),
            ),
            data=self.data.astype(np.int8).reshape(-1),
        )
        if stamp is not None:
            msg.header.stamp = stamp
            msg.info.map_load_time = stamp
        return msg

    @classmethod
    def from_msg(cls, msg: Any) -> OccupancyMap:
        info = msg.info
        w, h = int(info.width), int(info.height)
        data = np.asarray(msg.data, dtype=np.int8)
        if data.size != w * h:
            raise MapError(f"OccupancyGrid: width x height = {w} x {h} = {w * h} cells, but data holds {data.size}")
        q = info.origin.orientation
        yaw = math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z))
        return cls(data.reshape(h, w).copy(), float(info.resolution), (float(info.origin.position.x), float(info.origin.position.y), yaw),
                   str(msg.header.frame_id or "map"))


_REQUIRED = ("image", "resolution", "origin")


def load_map(path: str | Path) -> tuple[OccupancyMap, dict[str, Any]]:
    """Load a map_server YAML and its image; returns the map and the YAML document (extra keys kept)."""
    import cv2
    from ruamel.yaml import YAML
    from ruamel.yaml.error import YAMLError

    path = Path(path)
    if not path.is_file():
        raise MapError(f"{path}: no such map file (expected a map_server YAML)")
    try:
        doc = YAML(typ="safe").load(path.read_text(encoding="utf8"))
    except YAMLError as err:
        raise MapError(f"{path}: not valid YAML ({str(err).splitlines()[0]})") from None
    if not isinstance(doc, dict):
        raise MapError(f"{path}: expected a YAML mapping with {', '.join(_REQUIRED)}, found {type(doc).__name__}")
    for key in _REQUIRED:
        if key not in doc:
            raise MapError(f"{path}: missing key '{key}' (a map_server YAML needs {', '.join(_REQUIRED)})")
    try:
        resolution = float(doc["resolution"])
        origin = [float(v) for v in doc["origin"]]
        occupied_thresh = float(doc.get("occupied_thresh", 0.65))
        free_thresh = float(doc.get("free_thresh", 0.196))
        negate = int(doc.get("negate", 0))
    except (TypeError, ValueError) as err:
        raise MapError(f"{path}: resolution, origin, occupied_thresh, free_thresh must be numbers ({err})") from None
    if not resolution > 0:
        raise MapError(f"{path}: resolution must be > 0, found {resolution}")
    if len(origin) != 3:
        raise MapError(f"{path}: origin must be [x, y, yaw], found {doc['origin']!r}")
    if not 0 <= free_thresh < occupied_thresh <= 1:
        raise MapError(f"{path}: need 0 <= free_thresh < occupied_thresh <= 1, found {free_thresh}, {occupied_thresh}")
    mode = str(doc.get("mode", "trinary"))
    if mode not in ("trinary", "scale", "raw"):
        raise MapError(f"{path}: mode must be trinary, scale or raw, found {mode!r}")
    image_path = (path.parent / str(doc["image"])).resolve()
    image = cv2.imread(str(image_path), cv2.IMREAD_UNCHANGED) if image_path.is_file() else None
    if image is None:
        raise MapError(f"{path}: image {doc['image']!r} {'cannot be read as an image' if image_path.is_file() else 'does not exist'} ({image_path})")
    if image.ndim == 3:
        image = image[:, :, :3].mean(axis=2) if image.shape[2] >= 3 else image[:, :, 0]
    pixels = np.asarray(image, dtype=np.float64)
    if pixels.max(initial=0) > 255:
        raise MapError(f"{path}: image {doc['image']!r} has values above 255; expected an 8-bit greyscale map")
    if mode == "raw":
        data = pixels.astype(np.int16)
    else:
        occ = pixels / 255.0 if negate else (255.0 - pixels) / 255.0
        data = np.full(pixels.shape, -1, dtype=np.int16)
        data[occ > occupied_thresh] = 100
        data[occ < free_thresh] = 0
        if mode == "scale":
            between = (occ >= free_thresh) & (occ <= occupied_thresh)
            data[between] = np.round(99 * (occ[between] - free_thresh) / (occupied_thresh - free_thresh)).astype(np.int16)
    grid = np.flipud(data).astype(np.int8)
    return OccupancyMap(np.ascontiguousarray(grid), resolution, (origin[0], origin[1], origin[2])), doc


def save_map(occupancy: OccupancyMap, path: str | Path, *, extra: dict[str, Any] | None = None) -> Path:
    """Write ``<path>.yaml`` and ``<path>.pgm`` as map_saver does; returns the YAML path."""
    import cv2
    from ruamel.yaml import YAML

    base = Path(path)
    if base.suffix in (".yaml", ".yml", ".pgm"):
        base = base.with_suffix("")
    image = np.full(occupancy.data.shape, 205, dtype=np.uint8)
    image[occupancy.data == 0] = 254
    image[occupancy.data >= 65] = 0
    image[(occupancy.data > 0) & (occupancy.data < 65)] = 205
    base.parent.mkdir(parents=True, exist_ok=True)
    if not cv2.imwrite(str(base.with_suffix(".pgm")), np.flipud(image)):
        raise MapError(f"{base.with_suffix('.pgm')}: cannot write the map image")
    doc = {
        "image": base.with_suffix(".pgm").name,
        "mode": "trinary",
        "resolution": float(occupancy.resolution),
        "origin": [float(v) for v in occupancy.origin],
        "negate": 0,
        "occupied_thresh": 0.65,
        "free_thresh": 0.196,  # keeps 205 (unknown) unknown on reload: (255 - 205) / 255 = 0.196 is not below it
        **(extra or {}),
    }
    yaml = YAML(typ="safe")
    yaml.default_flow_style = None
    with open(base.with_suffix(".yaml"), "w", encoding="utf8") as f:
        yaml.dump(doc, f)
    return base.with_suffix(".yaml")
