"""Conversions between tf's internal numbers and ROS messages and times.

Message classes are imported on first use, so the buffer core imports without
``aiorobot.msgs``; messages are read by attribute, so any object with the ROS
field names works as input.
"""

from __future__ import annotations

from typing import Any

from aiorobot._core._time import Time

from ._math import Quat, Vec

__all__ = ["make_transform_stamped", "time_from_ns", "time_ns", "stamp_msg"]

_NS = 1_000_000_000


def time_ns(time: Any) -> int:
    """Integer nanoseconds of an ``aiorobot.Time`` or a ``builtin_interfaces/Time`` message.

    Raises
    ------
    TypeError
        For anything else (plain numbers are ambiguous: seconds or nanoseconds?).
    """
    if isinstance(time, Time):
        return time.nanoseconds
    sec = getattr(time, "sec", None)
    nanosec = getattr(time, "nanosec", None)
    if sec is not None and nanosec is not None:
        return int(sec) * _NS + int(nanosec)
    ns = getattr(time, "nanoseconds", None)
    if isinstance(ns, int) and not isinstance(time, (int, float)):
        return ns  # rclpy-style Time objects
    raise TypeError(
        "expected an aiorobot.Time or a builtin_interfaces/msg/Time message, got "
        f"{type(time).__name__} {time!r}; write Time(seconds=...) or Time() for the latest"
    )


def time_from_ns(ns: int) -> Time:
    return Time(nanoseconds=ns)


def stamp_msg(ns: int) -> Any:
    """A ``builtin_interfaces/msg/Time`` for ``ns`` nanoseconds."""
    from aiorobot.msgs.builtin_interfaces import Time as TimeMsg

    sec, nanosec = divmod(ns, _NS)
    return TimeMsg(sec=sec, nanosec=nanosec)


_classes: tuple[type, ...] | None = None


def _transform_classes() -> tuple[type, ...]:
    global _classes
    if _classes is None:
        from aiorobot.msgs.builtin_interfaces import Time as TimeMsg
        from aiorobot.msgs.geometry_msgs import Quaternion, Transform, TransformStamped, Vector3
        from aiorobot.msgs.std_msgs import Header

        _classes = (TransformStamped, Header, TimeMsg, Transform, Vector3, Quaternion)
    return _classes


def make_transform_stamped(frame_id: str, child_frame_id: str, stamp_ns: int, t: Vec, q: Quat) -> Any:
    """A ``geometry_msgs/msg/TransformStamped`` holding ``child2frame``.

    Built field by field without the constructors' argument handling: every value
    here is already of its field's type (str, int in range, float), and a lookup
    makes one of these per call, so the constructors' cost would dominate it.
    """
    ts_cls, header_cls, time_cls, transform_cls, vector_cls, quat_cls = _classes or _transform_classes()
    new = object.__new__
    stamp = new(time_cls)
    stamp.sec, stamp.nanosec = divmod(stamp_ns, _NS)
    header = new(header_cls)
    header.stamp = stamp
    header.frame_id = frame_id
    translation = new(vector_cls)
    translation.x, translation.y, translation.z = t
    rotation = new(quat_cls)
    rotation.x, rotation.y, rotation.z, rotation.w = q
    transform = new(transform_cls)
    transform.translation = translation
    transform.rotation = rotation
    msg = new(ts_cls)
    msg.header = header
    msg.child_frame_id = child_frame_id
    msg.transform = transform
    return msg


def transform_stamped_parts(msg: Any) -> tuple[str, str, int, Vec, Quat]:
    """(frame_id, child_frame_id, stamp_ns, translation, rotation) of a TransformStamped."""
    tr = msg.transform.translation
    ro = msg.transform.rotation
    return (
        msg.header.frame_id,
        msg.child_frame_id,
        time_ns(msg.header.stamp),
        (float(tr.x), float(tr.y), float(tr.z)),
        (float(ro.x), float(ro.y), float(ro.z), float(ro.w)),
    )
