"""``sensor_msgs_py`` (ROS 2's PointCloud2 helpers) for programs under ``aiorobot exec``: aiorobot.msgs.point_cloud2."""

from . import point_cloud2

__all__ = ["point_cloud2"]
