"""``sensor_msgs_py.point_cloud2``: :mod:`aiorobot.msgs.point_cloud2`."""

from ...msgs.point_cloud2 import (
    DUMMY_FIELD_PREFIX,
    create_cloud,
    create_cloud_xyz32,
    dtype_from_fields,
    read_points,
    read_points_list,
    read_points_numpy,
)

__all__ = [
    "DUMMY_FIELD_PREFIX",
    "create_cloud",
    "create_cloud_xyz32",
    "dtype_from_fields",
    "read_points",
    "read_points_list",
    "read_points_numpy",
]
