"""``sensor_msgs_py.point_cloud2``: :mod:`aiorobot.msgs.point_cloud2`."""

from ...msgs import point_cloud2 as _impl
from ...msgs.point_cloud2 import *  # noqa: F403

__all__ = list(_impl.__all__)
