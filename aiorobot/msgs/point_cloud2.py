"""sensor_msgs/PointCloud2 to and from numpy, as ROS 2's ``sensor_msgs_py.point_cloud2``.

The same functions, arguments and results: ``read_points`` gives a structured array
(one named field per PointField, a field with ``count > 1`` split into ``name_0``,
``name_1``, ...), ``read_points_numpy`` a plain ``(N, fields)`` array when every field
has one type, ``read_points_list`` named tuples; ``create_cloud`` builds a message from
a plain or structured array (or any iterable of points), ``create_cloud_xyz32`` one of
x, y, z float32. Under ``aiorobot exec``, ``from sensor_msgs_py import point_cloud2``
imports this module. As upstream, a cloud or points that do not fit raise
``AssertionError`` (explicitly, so ``python -O`` keeps the checks), naming what is wrong.
"""

from __future__ import annotations

import sys
from collections import namedtuple
from collections.abc import Iterable, Sequence
from typing import Any, NamedTuple

import numpy as np
from numpy.lib.recfunctions import structured_to_unstructured, unstructured_to_structured

from .sensor_msgs import PointCloud2, PointField

__all__ = [
    "DUMMY_FIELD_PREFIX",
    "create_cloud",
    "create_cloud_xyz32",
    "dtype_from_fields",
    "read_points",
    "read_points_list",
    "read_points_numpy",
]

_DATATYPES: dict[int, np.dtype[Any]] = {
    PointField.INT8: np.dtype(np.int8),
    PointField.UINT8: np.dtype(np.uint8),
    PointField.INT16: np.dtype(np.int16),
    PointField.UINT16: np.dtype(np.uint16),
    PointField.INT32: np.dtype(np.int32),
    PointField.UINT32: np.dtype(np.uint32),
    PointField.FLOAT32: np.dtype(np.float32),
    PointField.FLOAT64: np.dtype(np.float64),
}

#: the name given to a PointField whose name is empty (``unnamed_field_<index>``)
DUMMY_FIELD_PREFIX = "unnamed_field"


def _require(ok: bool, message: str) -> None:
    if not ok:
        raise AssertionError(message)


def dtype_from_fields(fields: Iterable[Any], point_step: int | None = None) -> np.dtype[Any]:
    """The numpy dtype of one point described by ``fields`` (``itemsize`` = ``point_step`` if given)."""
    names: list[str] = []
    offsets: list[int] = []
    formats: list[str] = []
    for i, field in enumerate(fields):
        datatype = _DATATYPES.get(field.datatype)
        _require(
            datatype is not None,
            f"PointField {field.name!r}: expected a datatype among PointField.INT8 ... FLOAT64 (1-8), "
            f"found {field.datatype!r}",
        )
        assert datatype is not None
        name = field.name or f"{DUMMY_FIELD_PREFIX}_{i}"
        _require(field.count > 0, f"PointField {name!r}: can't process fields with count = {field.count}")
        for k in range(field.count):
            sub = f"{name}_{k}" if field.count > 1 else name
            _require(sub not in names, f"duplicate field name {sub!r} in the point cloud's fields")
            names.append(sub)
            offsets.append(field.offset + k * datatype.itemsize)
            formats.append(datatype.str)
    spec: dict[str, Any] = {"names": names, "formats": formats, "offsets": offsets}
    if point_step is not None:
        spec["itemsize"] = point_step
    return np.dtype(spec)


def read_points(
    cloud: Any,
    field_names: Sequence[str] | None = None,
    skip_nans: bool = False,
    uvs: Iterable[int] | None = None,
    reshape_organized_cloud: bool = False,
) -> np.ndarray[Any, Any]:
    """The cloud's points as a structured array (a view of ``cloud.data`` where it can be)."""
    _require(isinstance(cloud, PointCloud2), f"expected a sensor_msgs/PointCloud2, found {type(cloud).__name__}")
    count = cloud.width * cloud.height
    dtype = dtype_from_fields(cloud.fields, point_step=cloud.point_step)
    data = cloud.data if isinstance(cloud.data, (bytes, bytearray, memoryview)) else np.asarray(cloud.data, np.uint8)
    _require(
        len(data) >= count * dtype.itemsize,
        f"PointCloud2 data holds {len(data)} bytes; width x height x point_step = "
        f"{cloud.width} x {cloud.height} x {dtype.itemsize} = {count * dtype.itemsize}",
    )
    points = np.ndarray(shape=(count,), dtype=dtype, buffer=data)
    if field_names is not None:
        missing = [n for n in field_names if n not in (points.dtype.names or ())]
        _require(not missing, f"fields {missing} are not among the cloud's fields {list(points.dtype.names or ())}")
        points = points[list(field_names)]
    if (sys.byteorder != "little") != bool(cloud.is_bigendian):
        points = points.byteswap()
    if skip_nans and not cloud.is_dense:
        keep = np.ones(len(points), dtype=bool)
        for name in points.dtype.names or ():
            column = points[name]
            if np.issubdtype(column.dtype, np.floating):
                keep &= ~np.isnan(column)
        points = points[keep]
    if uvs is not None:
        index = uvs if isinstance(uvs, np.ndarray) else np.fromiter(uvs, int)
        points = points[index]
    if reshape_organized_cloud and cloud.height > 1:
        points = points.reshape(cloud.width, cloud.height)
    return points


def read_points_numpy(
    cloud: Any,
    field_names: Sequence[str] | None = None,
    skip_nans: bool = False,
    uvs: Iterable[int] | None = None,
    reshape_organized_cloud: bool = False,
) -> np.ndarray[Any, Any]:
    """The chosen fields as a plain ``(N, len(fields))`` array; they must share one datatype."""
    chosen = [f for f in cloud.fields if field_names is None or f.name in field_names]
    _require(
        all(f.datatype == chosen[0].datatype for f in chosen[1:]),
        "read_points_numpy: all fields need the same datatype "
        f"({', '.join(f'{f.name}={f.datatype}' for f in chosen)}); use read_points() otherwise",
    )
    return structured_to_unstructured(read_points(cloud, field_names, skip_nans, uvs, reshape_organized_cloud))


def read_points_list(
    cloud: Any,
    field_names: Sequence[str] | None = None,
    skip_nans: bool = False,
    uvs: Iterable[int] | None = None,
) -> list[NamedTuple]:
    """The points as a list of ``Point`` named tuples (slow; ``read_points`` is the fast way)."""
    _require(isinstance(cloud, PointCloud2), f"expected a sensor_msgs/PointCloud2, found {type(cloud).__name__}")
    names = list(field_names) if field_names is not None else [f.name for f in cloud.fields]
    point = namedtuple("Point", names)  # type: ignore[misc]
    return [point._make(p) for p in read_points(cloud, names, skip_nans, uvs)]


def create_cloud(header: Any, fields: Sequence[Any], points: Any, point_step: int | None = None) -> Any:
    """A PointCloud2 of ``points``: an ``(N, fields)`` array, a structured array, or rows of values.

    A 2-D array of points (``(width, height)`` of a structured dtype) makes an organised cloud.
    """
    dtype = dtype_from_fields(fields, point_step)
    if isinstance(points, np.ndarray):
        if points.dtype.names is None:
            _require(
                all(f.datatype == fields[0].datatype for f in fields[1:]),
                "create_cloud: a plain array needs fields of one datatype; pass a structured array otherwise",
            )
            _require(
                points.ndim >= 1 and points.shape[-1] == len(dtype.names or ()),
                f"create_cloud: expected points of shape (N, {len(dtype.names or ())}) for fields "
                f"{list(dtype.names or ())}, found {points.shape}",
            )
            points = unstructured_to_structured(np.ascontiguousarray(points), dtype=dtype)
        else:
            _require(
                points.dtype == dtype,
                f"create_cloud: the structured array's dtype {points.dtype} does not match the fields' {dtype}",
            )
    else:
        points = np.array([tuple(p) for p in points], dtype=dtype)
    _require(points.ndim <= 2, f"create_cloud: an organised cloud has at most 2 dimensions, found {points.ndim}")
    width = points.shape[0]
    height = points.shape[1] if points.ndim == 2 else 1
    cloud = PointCloud2(
        header=header,
        height=height,
        width=width,
        is_dense=False,
        is_bigendian=sys.byteorder != "little",
        fields=list(fields),
        point_step=points.dtype.itemsize,
        row_step=points.dtype.itemsize * width,
    )
    cloud.data = np.frombuffer(np.ascontiguousarray(points).tobytes(), dtype=np.uint8)
    return cloud


def create_cloud_xyz32(header: Any, points: Any) -> Any:
    """A PointCloud2 of x, y, z float32 fields."""
    fields = [
        PointField(name="x", offset=0, datatype=PointField.FLOAT32, count=1),
        PointField(name="y", offset=4, datatype=PointField.FLOAT32, count=1),
        PointField(name="z", offset=8, datatype=PointField.FLOAT32, count=1),
    ]
    return create_cloud(header, fields, points)
