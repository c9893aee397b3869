"""``tf2_geometry_msgs`` on aiorobot: ``do_transform_*`` for geometry_msgs, registered for ``Buffer.transform``.

Importing it registers the types with tf2_ros, as upstream, so ``buffer.transform(point_stamped,
"map")`` works.
"""

from __future__ import annotations

from ._transforms import (
    do_transform_point,
    do_transform_polygon_stamped,
    do_transform_pose,
    do_transform_pose_stamped,
    do_transform_pose_with_covariance_stamped,
    do_transform_vector3,
    from_msg_msg,
    register,
    to_msg_msg,
    transform_covariance,
)

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

register()
