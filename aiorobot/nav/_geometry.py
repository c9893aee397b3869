"""Small pose helpers shared by the navigation nodes (messages <-> (x, y, yaw))."""

from __future__ import annotations

import math
from typing import Any

__all__ = ["pose_stamped", "transform_to_xyyaw", "wrap_angle", "xyyaw", "yaw_quaternion"]


def wrap_angle(a: float) -> float:
    """``a`` (rad) wrapped into [-pi, pi) (angles::normalize_angle, but -pi for +pi)."""
    return (a + math.pi) % (2 * math.pi) - math.pi


def yaw_quaternion(yaw: float) -> Any:
    from aiorobot.msgs.geometry_msgs import Quaternion

    return Quaternion(z=math.sin(yaw / 2.0), w=math.cos(yaw / 2.0))


def _yaw(q: Any) -> float:
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def xyyaw(pose: Any) -> tuple[float, float, float]:
    """(x, y, yaw) of a geometry_msgs Pose or PoseStamped."""
    p = getattr(pose, "pose", pose)
    return float(p.position.x), float(p.position.y), _yaw(p.orientation)


def transform_to_xyyaw(t: Any) -> tuple[float, float, float]:
    """(x, y, yaw) of a TransformStamped."""
    tr = t.transform
    return float(tr.translation.x), float(tr.translation.y), _yaw(tr.rotation)


def pose_stamped(x: float, y: float, yaw: float, frame_id: str = "map", stamp: Any = None) -> Any:
    from aiorobot.msgs.geometry_msgs import Point, Pose, PoseStamped
    from aiorobot.msgs.std_msgs import Header

    msg = PoseStamped(header=Header(frame_id=frame_id), pose=Pose(position=Point(x=float(x), y=float(y)), orientation=yaw_quaternion(yaw)))
    if stamp is not None:
        msg.header.stamp = stamp
    return msg
