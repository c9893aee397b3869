"""aiorobot.msgs.point_cloud2, restating sensor_msgs_py's test_point_cloud2.py (ros2/common_interfaces)."""

from __future__ import annotations

import sys

import numpy as np
import pytest
from numpy.lib.recfunctions import structured_to_unstructured, unstructured_to_structured

from aiorobot.msgs import point_cloud2
from aiorobot.msgs.sensor_msgs import PointCloud2, PointField
from aiorobot.msgs.std_msgs import Header

PYLIST = [(0.0, 0.1, 0.2), (1.0, 1.1, 1.2), (2.0, 2.1, 2.2), (3.0, 3.1, 3.2), (4.0, np.nan, 4.2), (5.0, 5.1, 5.2)]
POINTS = np.array(PYLIST, dtype=np.float32)
FIELDS = [PointField(name=n, offset=4 * i, datatype=PointField.FLOAT32, count=1) for i, n in enumerate("xyz")]
BIG = sys.byteorder != "little"


def cloud(fields, data, width, height=1, point_step=12):
    return PointCloud2(
        header=Header(frame_id="frame"), height=height, width=width, is_dense=False, is_bigendian=BIG,
        fields=fields, point_step=point_step, row_step=point_step * width, data=data,
    )


PCD = cloud(FIELDS, POINTS.tobytes(), 6)
POINTS3 = POINTS.reshape(2, 3, -1)
PCD3 = cloud(FIELDS, POINTS3.tobytes(), 2, 3)
STRUCT = np.array(list(map(tuple, POINTS)), dtype=[("a", np.float32), ("b", np.float64), ("c", np.uint8)])
STRUCT_FIELDS = [
    PointField(name="a", offset=0, datatype=PointField.FLOAT32, count=1),
    PointField(name="b", offset=4, datatype=PointField.FLOAT64, count=1),
    PointField(name="c", offset=12, datatype=PointField.UINT8, count=1),
]
PCD4 = cloud(STRUCT_FIELDS, STRUCT.tobytes(), 6, point_step=STRUCT.itemsize)
FIELDS5 = [PointField(name="x", offset=0, datatype=PointField.FLOAT32, count=3)]
PCD5 = cloud(FIELDS5, POINTS.tobytes(), 6)


def same_cloud(a, b) -> bool:
    return (
        a.header.frame_id == b.header.frame_id and (a.width, a.height, a.point_step, a.row_step) == (b.width, b.height, b.point_step, b.row_step)
        and a.is_bigendian == b.is_bigendian and a.is_dense == b.is_dense and list(a.fields) == list(b.fields)
        and bytes(np.asarray(a.data, np.uint8)) == bytes(np.asarray(b.data, np.uint8))
    )


def test_read_points():
    assert np.allclose([list(p) for p in point_cloud2.read_points(PCD)], PYLIST, equal_nan=True)


def test_read_points_field():
    got = np.array([list(p) for p in point_cloud2.read_points(PCD, field_names=("x", "z"))])
    assert got.shape == (6, 2) and np.allclose(got, POINTS[:, [0, 2]], equal_nan=True)


def test_read_points_skip_nan():
    got = np.array([list(p) for p in point_cloud2.read_points(PCD, skip_nans=True)])
    keep = ~np.isnan(POINTS).any(axis=1)
    assert got.shape == POINTS[keep].shape and np.allclose(got, POINTS[keep])


def test_read_points_list_gives_named_tuples():
    got = point_cloud2.read_points_list(PCD)
    assert got[1].x == pytest.approx(1.0) and got[1].z == pytest.approx(1.2)
    assert np.allclose([list(p) for p in got], PYLIST, equal_nan=True)


def test_read_points_organized():
    assert np.allclose([list(p) for p in point_cloud2.read_points(PCD3)], PYLIST, equal_nan=True)
    organised = structured_to_unstructured(point_cloud2.read_points(PCD3, reshape_organized_cloud=True))
    assert np.allclose(organised, POINTS3, equal_nan=True)


def test_read_points_numpy_needs_one_datatype():
    assert np.allclose(point_cloud2.read_points_numpy(PCD), POINTS, equal_nan=True)
    with pytest.raises(AssertionError, match="same datatype"):
        point_cloud2.read_points_numpy(PCD4)


def test_read_points_numpy_specific_fields():
    struct6 = np.array(list(map(tuple, POINTS)), dtype=[("a", np.float32), ("b", np.float32), ("c", np.uint8)])
    fields6 = [
        PointField(name="a", offset=0, datatype=PointField.FLOAT32, count=1),
        PointField(name="b", offset=4, datatype=PointField.FLOAT32, count=1),
        PointField(name="c", offset=8, datatype=PointField.UINT8, count=1),
    ]
    pcd6 = cloud(fields6, struct6.tobytes(), 6, point_step=struct6.itemsize)
    assert point_cloud2.read_points_numpy(pcd6, field_names=("a", "b")).shape == (6, 2)


def test_read_points_different_types():
    got = point_cloud2.read_points(PCD4)
    assert got.dtype == STRUCT.dtype
    assert all(np.allclose(got[n], STRUCT[n], equal_nan=True) for n in STRUCT.dtype.names)


def test_a_field_with_count_three_is_split_into_subfields():
    assert np.allclose(point_cloud2.read_points_numpy(PCD5), POINTS, equal_nan=True)
    assert point_cloud2.read_points(PCD5).dtype.names == ("x_0", "x_1", "x_2")


def test_create_cloud():
    assert same_cloud(point_cloud2.create_cloud(Header(frame_id="frame"), FIELDS, PYLIST), PCD)
    assert not same_cloud(point_cloud2.create_cloud(Header(frame_id="frame2"), FIELDS, PYLIST), PCD)
    fields2 = FIELDS[1:]
    assert not same_cloud(point_cloud2.create_cloud(Header(frame_id="frame"), fields2, POINTS[:, 1:].tolist()), PCD)


def test_create_cloud_itemsize():
    padded = np.array(PYLIST, dtype=np.dtype({"names": list("xyz"), "formats": ["f4"] * 3, "offsets": [0, 4, 8], "itemsize": 20}))
    with pytest.raises(AssertionError, match="does not match"):
        point_cloud2.create_cloud(Header(frame_id="frame"), FIELDS, padded)
    assert point_cloud2.create_cloud(Header(frame_id="frame"), FIELDS, padded, 20).point_step == 20


def test_create_cloud_different_types_xyz32_organised_and_count():
    assert same_cloud(point_cloud2.create_cloud(Header(frame_id="frame"), STRUCT_FIELDS, STRUCT), PCD4)
    assert same_cloud(point_cloud2.create_cloud_xyz32(Header(frame_id="frame"), PYLIST), PCD)
    assert same_cloud(point_cloud2.create_cloud_xyz32(Header(frame_id="frame"), POINTS3), PCD3)
    assert same_cloud(point_cloud2.create_cloud(Header(frame_id="frame"), FIELDS5, POINTS), PCD5)


def test_read_cloud_with_non_standard_point_step():
    wide = np.array(
        unstructured_to_structured(POINTS),
        dtype=np.dtype({"names": list("xyz"), "formats": ["<f4"] * 3, "offsets": [0, 4, 8], "itemsize": 123}),
    )
    pc = cloud(FIELDS, wide.tobytes(), 6, point_step=123)
    assert np.allclose(point_cloud2.read_points_numpy(pc), POINTS, equal_nan=True)


def test_bad_clouds_say_what_is_wrong():
    short = cloud(FIELDS, POINTS.tobytes()[:-4], 6)
    with pytest.raises(AssertionError, match="holds 68 bytes"):
        point_cloud2.read_points(short)
    with pytest.raises(AssertionError, match="datatype"):
        point_cloud2.dtype_from_fields([PointField(name="x", offset=0, datatype=42, count=1)])
    with pytest.raises(AssertionError, match=r"shape \(N, 3\)"):
        point_cloud2.create_cloud(Header(), FIELDS, np.zeros((4, 2), np.float32))
    with pytest.raises(AssertionError, match="not among the cloud's fields"):
        point_cloud2.read_points(PCD, field_names=["w"])
