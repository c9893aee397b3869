"""``tf2_geometry_msgs`` on aiorobot: ``do_transform_*`` for geometry_msgs, registered for ``Buffer.transform``.

Importing it registers the types with tf2_ros, as upstream, so ``buffer.transform(point_stamped,
"map")`` works.
"""

from __future__ import annotations

from . import _transforms
from ._transforms import *  # noqa: F403 - the package is its do_transform_* functions

__all__ = list(_transforms.__all__)

_transforms.register()
