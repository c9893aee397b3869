"""Applying a transform to stamped geometry messages (tf2_geometry_msgs' ``do_transform``).

Supported: ``PointStamped``, ``Vector3Stamped`` (rotation only: a vector has no
position), ``PoseStamped``, ``QuaternionStamped`` and ``TransformStamped``.
Results are new messages of the input's class, with ``header.frame_id`` set to
the transform's target frame and ``header.stamp`` to the transform's stamp.
"""

from __future__ import annotations

from typing import Any, Callable

from ._math import Quat, Vec, _canonical, _qmul, _qrot

__all__ = ["SUPPORTED_TYPES", "do_transform", "msgtype_of"]


def msgtype_of(msg: Any) -> str:
    return str(getattr(msg, "__msgtype__", type(msg).__name__))


def _header(msg: Any, frame_id: str, stamp: Any) -> Any:
    return type(msg.header)(stamp=stamp, frame_id=frame_id)


def _vec_like(proto: Any, v: Vec) -> Any:
    return type(proto)(x=v[0], y=v[1], z=v[2])


def _quat_like(proto: Any, q: Quat) -> Any:
    return type(proto)(x=q[0], y=q[1], z=q[2], w=q[3])


def _xyz(v: Any) -> Vec:
    return (float(v.x), float(v.y), float(v.z))


def _xyzw(q: Any, what: str = "quaternion") -> Quat:
    out = (float(q.x), float(q.y), float(q.z), float(q.w))
    if not any(out):
        raise ValueError(f"the {what} is (0, 0, 0, 0), which is no rotation; the identity is (0, 0, 0, 1)")
    return out


def _apply(t: Vec, q: Quat, p: Vec) -> Vec:
    r = _qrot(q, p)
    return (r[0] + t[0], r[1] + t[1], r[2] + t[2])


def _point(msg: Any, t: Vec, q: Quat, frame_id: str, stamp: Any) -> Any:
    return type(msg)(header=_header(msg, frame_id, stamp), point=_vec_like(msg.point, _apply(t, q, _xyz(msg.point))))


def _vector(msg: Any, t: Vec, q: Quat, frame_id: str, stamp: Any) -> Any:
    return type(msg)(header=_header(msg, frame_id, stamp), vector=_vec_like(msg.vector, _qrot(q, _xyz(msg.vector))))


def _pose(msg: Any, t: Vec, q: Quat, frame_id: str, stamp: Any) -> Any:
    pose = msg.pose
    position = _apply(t, q, _xyz(pose.position))
    orientation = _canonical(_qmul(q, _xyzw(pose.orientation, "pose's orientation")))
    out_pose = type(pose)(
        position=_vec_like(pose.position, position),
        orientation=_quat_like(pose.orientation, orientation),
    )
    return type(msg)(header=_header(msg, frame_id, stamp), pose=out_pose)


def _quaternion(msg: Any, t: Vec, q: Quat, frame_id: str, stamp: Any) -> Any:
    # as tf2_geometry_msgs: the plain product, no sign normalisation
    out = _qmul(q, _xyzw(msg.quaternion, "quaternion to transform"))
    return type(msg)(header=_header(msg, frame_id, stamp), quaternion=_quat_like(msg.quaternion, out))


def _transform(msg: Any, t: Vec, q: Quat, frame_id: str, stamp: Any) -> Any:
    tr = msg.transform
    translation = _apply(t, q, _xyz(tr.translation))
    rotation = _canonical(_qmul(q, _xyzw(tr.rotation, "transform's rotation")))
    out_tr = type(tr)(
        translation=_vec_like(tr.translation, translation),
        rotation=_quat_like(tr.rotation, rotation),
    )
    return type(msg)(header=_header(msg, frame_id, stamp), child_frame_id=msg.child_frame_id, transform=out_tr)


_HANDLERS: dict[str, Callable[[Any, Vec, Quat, str, Any], Any]] = {
    "geometry_msgs/msg/PointStamped": _point,
    "geometry_msgs/msg/Vector3Stamped": _vector,
    "geometry_msgs/msg/PoseStamped": _pose,
    "geometry_msgs/msg/QuaternionStamped": _quaternion,
    "geometry_msgs/msg/TransformStamped": _transform,
}
SUPPORTED_TYPES = tuple(_HANDLERS)


def check_supported(msg: Any) -> Callable[[Any, Vec, Quat, str, Any], Any]:
    handler = _HANDLERS.get(msgtype_of(msg))
    if handler is None:
        raise TypeError(
            f"cannot transform a {msgtype_of(msg)}; supported types are " + ", ".join(SUPPORTED_TYPES)
        )
    return handler


def do_transform(msg: Any, transform: Any) -> Any:
    """Apply a ``TransformStamped`` (``source`` -> ``target``) to a stamped message.

    ``transform.child_frame_id`` should equal ``msg.header.frame_id``; the result
    is expressed in ``transform.header.frame_id``.
    """
    handler = check_supported(msg)
    tr = transform.transform
    return handler(msg, _xyz(tr.translation), _xyzw(tr.rotation), transform.header.frame_id, transform.header.stamp)
