"""Builders for the messages the tf tests feed to a Buffer."""

from __future__ import annotations

import math
from typing import Sequence

from aiorobot import Time
from aiorobot.msgs.builtin_interfaces import Time as TimeMsg
from aiorobot.msgs.geometry_msgs import Quaternion, Transform, TransformStamped, Vector3
from aiorobot.msgs.std_msgs import Header

IDENTITY = (0.0, 0.0, 0.0, 1.0)


def stamp(sec: float) -> TimeMsg:
    return Time(seconds=sec).to_msg()


def yaw_q(yaw: float) -> tuple[float, float, float, float]:
    return (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2))


def tf(
    parent: str,
    child: str,
    sec: float = 0.0,
    xyz: Sequence[float] = (0.0, 0.0, 0.0),
    q: Sequence[float] = IDENTITY,
) -> TransformStamped:
    return TransformStamped(
        header=Header(stamp=stamp(sec), frame_id=parent),
        child_frame_id=child,
        transform=Transform(
            translation=Vector3(x=xyz[0], y=xyz[1], z=xyz[2]),
            rotation=Quaternion(x=q[0], y=q[1], z=q[2], w=q[3]),
        ),
    )


def xyz_of(msg: TransformStamped) -> tuple[float, float, float]:
    t = msg.transform.translation
    return (t.x, t.y, t.z)


def q_of(msg: TransformStamped) -> tuple[float, float, float, float]:
    r = msg.transform.rotation
    return (r.x, r.y, r.z, r.w)


def sec_of(msg: TransformStamped) -> float:
    return Time.from_msg(msg.header.stamp).nanoseconds / 1e9
