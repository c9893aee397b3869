"""PointCloud2 <-> (N, 3) float arrays, and voxel-grid downsampling."""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from ._images import BadInput

__all__ = ["cloud_to_xyz", "voxel_downsample", "xyz_to_cloud"]


def xyz_to_cloud(points: NDArray[np.float64], frame_id: str = "", stamp: Any = None) -> Any:
    """A dense ``sensor_msgs/PointCloud2`` with float32 x, y, z fields from (N, 3) (or (N, 2), z = 0) points."""
    from aiorobot.msgs.sensor_msgs import PointCloud2, PointField

    pts = np.asarray(points, dtype=np.float32)
    if pts.ndim != 2 or pts.shape[1] not in (2, 3):
        raise ValueError(f"points must be (N, 2) or (N, 3), got shape {pts.shape}")
    if pts.shape[1] == 2:
        pts = np.column_stack((pts, np.zeros(len(pts), np.float32)))
    msg = PointCloud2()
    msg.header.frame_id = frame_id
    if stamp is not None:
        msg.header.stamp = stamp
    msg.height, msg.width = 1, len(pts)
    msg.fields = [PointField(name=n, offset=4 * i, datatype=PointField.FLOAT32, count=1) for i, n in enumerate("xyz")]
    msg.is_bigendian = False
    msg.point_step, msg.row_step = 12, 12 * len(pts)
    msg.data = np.ascontiguousarray(pts).view(np.uint8).ravel()
    msg.is_dense = True
    return msg


_DTYPES = {7: "<f4", 8: "<f8"}


def cloud_to_xyz(msg: Any) -> NDArray[np.float64]:
    """The x, y, z fields of a PointCloud2 as (N, 3) float64, non-finite points dropped."""
    fields = {f.name: f for f in msg.fields}
    if not {"x", "y", "z"} <= fields.keys():
        raise BadInput(f"PointCloud2 needs x, y, z fields, has {sorted(fields)}")
    n = int(msg.width) * int(msg.height)
    data = np.asarray(msg.data, dtype=np.uint8)
    if data.size != n * int(msg.point_step) or msg.point_step <= 0:
        raise BadInput(f"PointCloud2 data has {data.size} bytes, expected width*height*point_step = "
                       f"{msg.width}*{msg.height}*{msg.point_step}")
    rows = data.reshape(n, int(msg.point_step))
    columns = []
    for name in "xyz":
        f = fields[name]
        if f.datatype not in _DTYPES:
            raise BadInput(f"PointCloud2 field {name!r} has datatype {f.datatype}, expected FLOAT32 (7) or FLOAT64 (8)")
        dtype = np.dtype(_DTYPES[f.datatype]).newbyteorder(">" if msg.is_bigendian else "<")
        columns.append(rows[:, f.offset:f.offset + dtype.itemsize].copy().view(dtype).ravel())
    xyz = np.column_stack(columns).astype(np.float64)
    return xyz[np.all(np.isfinite(xyz), axis=1)]


def voxel_downsample(points: NDArray[np.float64], voxel_size: float) -> NDArray[np.float64]:
    """One point per occupied voxel (the centroid of its points), for (N, 3) points; sorted by voxel."""
    pts = np.asarray(points, dtype=np.float64)
    if pts.ndim != 2 or pts.shape[1] != 3:
        raise ValueError(f"points must be (N, 3), got shape {pts.shape}")
    if not voxel_size > 0.0:
        raise ValueError(f"voxel_size must be > 0, got {voxel_size}")
    if len(pts) == 0:
        return pts.copy()
    keys = np.floor(pts / voxel_size).astype(np.int64)
    _, inverse, counts = np.unique(keys, axis=0, return_inverse=True, return_counts=True)
    inverse = inverse.ravel()
    sums = np.zeros((len(counts), 3))
    np.add.at(sums, inverse, pts)
    return sums / counts[:, None]
