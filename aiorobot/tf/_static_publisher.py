"""The static transform publisher node: one fixed transform on ``/tf_static``.

As tf2_ros's ``static_transform_publisher`` (``StaticTransformBroadcasterNode``): read-only
parameters ``translation.x|y|z``, ``rotation.x|y|z|w`` (identity by default), ``frame_id`` and
``child_frame_id``; the transform is sent once, stamped with the node's clock at construction,
on the transient-local ``/tf_static`` so late subscribers receive it too. As on the program's
command line (``--roll --pitch --yaw``), the rotation may be given as ``roll``, ``pitch``,
``yaw`` (radians) instead of a quaternion.

In a config::

    [[nodes]]
    name = "map_to_odom"
    use = "aiorobot.tf:StaticTransformPublisher"
    parameters = { frame_id = "map", child_frame_id = "odom", "translation.x" = 1.0, yaw = 1.5708 }
"""

from __future__ import annotations

import math
from typing import Any

from aiorobot._core._node import Node
from aiorobot._core._parameter_types import ParameterDescriptor

from ._broadcasters import StaticTransformBroadcaster
from ._math import quaternion_from_euler
from ._msgs import make_transform_stamped

__all__ = ["StaticTransformPublisher"]

_TRANSLATION = ("translation.x", "translation.y", "translation.z")
_ROTATION = ("rotation.x", "rotation.y", "rotation.z", "rotation.w")
_EULER = ("roll", "pitch", "yaw")


class StaticTransformPublisher(Node):
    """Publishes ``frame_id -> child_frame_id`` once on ``/tf_static``.

    Raises
    ------
    ValueError
        At construction: ``frame_id`` equals ``child_frame_id`` (as tf2_ros), a value is not
        finite, the quaternion is not of unit length, or both a quaternion and roll/pitch/yaw
        are given. The message names the parameter.
    """

    def __init__(self, name: str = "static_transform_publisher", **kw: Any) -> None:
        super().__init__(name, **kw)
        read_only = ParameterDescriptor(read_only=True)
        translation = [float(self.declare_parameter(p, 0.0, read_only).value) for p in _TRANSLATION]
        quaternion = [float(self.declare_parameter(p, 1.0 if p == "rotation.w" else 0.0, read_only).value)
                      for p in _ROTATION]
        euler = [float(self.declare_parameter(p, 0.0, read_only).value) for p in _EULER]
        frame_id = self.declare_parameter("frame_id", "/frame", read_only).value
        child_frame_id = self.declare_parameter("child_frame_id", "/child", read_only).value

        where = self.get_fully_qualified_name()
        for names, values in ((_TRANSLATION, translation), (_ROTATION, quaternion), (_EULER, euler)):
            for p, v in zip(names, values):
                if not math.isfinite(v):
                    raise ValueError(f"{where}: parameter {p} must be a finite number, found {v}")
        if frame_id == child_frame_id:
            raise ValueError(
                f"{where}: cannot publish a static transform from {frame_id!r} to itself "
                "(frame_id must differ from child_frame_id)"
            )
        if any(euler):
            if quaternion != [0.0, 0.0, 0.0, 1.0]:
                raise ValueError(
                    f"{where}: give the rotation either as rotation.x/y/z/w or as roll/pitch/yaw, not both"
                )
            quaternion = [float(q) for q in quaternion_from_euler(*euler)]
        norm = math.sqrt(sum(q * q for q in quaternion))
        if abs(norm - 1.0) > 1e-3:
            raise ValueError(
                f"{where}: rotation.x/y/z/w must be a unit quaternion, found {quaternion} (length {norm:.4g})"
            )
        quaternion = [q / norm for q in quaternion]

        self.transform = make_transform_stamped(
            frame_id, child_frame_id, self.get_clock().now().nanoseconds, translation, quaternion
        )
        self._broadcaster = StaticTransformBroadcaster(self)
        self._broadcaster.send_transform(self.transform)
