"""tf2_geometry_msgs' ``do_transform_*`` on aiorobot.tf's maths, registered for ``Buffer.transform``.

Each applies a ``TransformStamped`` (source -> ``transform.header.frame_id``) to a geometry
message; stamped results carry the transform's header, as upstream.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from aiorobot.msgs.geometry_msgs import (
    Point32,
    PointStamped,
    PolygonStamped,
    Pose,
    PoseStamped,
    PoseWithCovarianceStamped,
    Vector3Stamped,
)

from ...tf import do_transform
from ...tf._conversions import _apply, _xyz, _xyzw
from ...tf._math import _canonical, _q_to_m, _qmul
from ..tf2_ros import ConvertRegistration, TransformRegistration

__all__ = [
    "do_transform_point",
    "do_transform_polygon_stamped",
    "do_transform_pose",
    "do_transform_pose_stamped",
    "do_transform_pose_with_covariance_stamped",
    "do_transform_vector3",
    "from_msg_msg",
    "to_msg_msg",
    "transform_covariance",
]


def to_msg_msg(msg: Any) -> Any:
    return msg


def from_msg_msg(msg: Any) -> Any:
    return msg


def _parts(transform: Any) -> tuple[tuple[float, float, float], tuple[float, float, float, float]]:
    tr = transform.transform
    return _xyz(tr.translation), _xyzw(tr.rotation, "transform's rotation")


def transform_covariance(cov_in: ArrayLike, transform: Any) -> NDArray[np.float64]:
    """A 6x6 pose covariance (36 values, row major) rotated by ``transform``: each 3x3 block R C R^T."""
    cov = np.asarray(cov_in, dtype=np.float64)
    if cov.size != 36:
        raise ValueError(f"transform_covariance: expected 36 covariance values (6x6), got {cov.size}")
    _, q = _parts(transform)
    R = np.array(_q_to_m(q), dtype=np.float64).reshape(3, 3)
    rot = np.zeros((6, 6))
    rot[:3, :3] = R
    rot[3:, 3:] = R
    return (rot @ cov.reshape(6, 6) @ rot.T).reshape(36)


def do_transform_point(point: Any, transform: Any) -> Any:
    """A ``PointStamped`` in the transform's target frame."""
    return do_transform(point, transform)


def do_transform_vector3(vector3: Any, transform: Any) -> Any:
    """A ``Vector3Stamped`` rotated into the transform's target frame (a vector has no position)."""
    return do_transform(vector3, transform)


def do_transform_pose(pose: Any, transform: Any) -> Any:
    """A ``Pose`` (unstamped) in the transform's target frame."""
    t, q = _parts(transform)
    p = _apply(t, q, _xyz(pose.position))
    o = _canonical(_qmul(q, _xyzw(pose.orientation, "pose's orientation")))
    res = Pose()
    res.position.x, res.position.y, res.position.z = p
    res.orientation.x, res.orientation.y, res.orientation.z, res.orientation.w = o
    return res


def do_transform_pose_stamped(pose: Any, transform: Any) -> Any:
    """A ``PoseStamped`` in the transform's target frame."""
    res = PoseStamped()
    res.pose = do_transform_pose(pose.pose, transform)
    res.header = transform.header
    return res


def do_transform_pose_with_covariance_stamped(pose: Any, transform: Any) -> Any:
    """A ``PoseWithCovarianceStamped`` in the transform's target frame, its covariance rotated."""
    res = PoseWithCovarianceStamped()
    res.pose.pose = do_transform_pose(pose.pose.pose, transform)
    res.pose.covariance = transform_covariance(pose.pose.covariance, transform)
    res.header = transform.header
    return res


def do_transform_polygon_stamped(polygon: Any, transform: Any) -> Any:
    """A ``PolygonStamped`` whose every point is in the transform's target frame."""
    t, q = _parts(transform)
    res = PolygonStamped()
    for point in polygon.polygon.points:
        x, y, z = _apply(t, q, _xyz(point))
        res.polygon.points.append(Point32(x=x, y=y, z=z))
    res.header = transform.header
    return res


def register() -> None:
    """Make ``Buffer.transform`` accept these types (done on import, as upstream)."""
    for msg_type in (Vector3Stamped, PoseStamped, PointStamped):
        ConvertRegistration().add_to_msg(msg_type, to_msg_msg)
        ConvertRegistration().add_from_msg(msg_type, from_msg_msg)
    registration = TransformRegistration()
    registration.add(PointStamped, do_transform_point)
    registration.add(Vector3Stamped, do_transform_vector3)
    registration.add(PoseStamped, do_transform_pose_stamped)
    registration.add(PoseWithCovarianceStamped, do_transform_pose_with_covariance_stamped)
    registration.add(PolygonStamped, do_transform_polygon_stamped)
