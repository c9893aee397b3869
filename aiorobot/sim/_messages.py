"""Building the simulator's ROS messages from plain numbers (no node state)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = ["odometry_message", "static_transform", "occupancy_grid_message"]


def odometry_message(stamp: Any, frame_id: str, child_frame_id: str, pose: NDArray[np.float64],
                     twist: NDArray[np.float64], pose_variance: tuple[float, float, float],
                     twist_variance: tuple[float, float, float]) -> Any:
    """``nav_msgs/Odometry`` of a planar pose ``(x, y, yaw)`` and body twist ``(vx, vy, omega)``."""
    from aiorobot.msgs.nav_msgs import Odometry

    msg = Odometry()
    msg.header.stamp = stamp
    msg.header.frame_id = frame_id
    msg.child_frame_id = child_frame_id
    msg.pose.pose.position.x = float(pose[0])
    msg.pose.pose.position.y = float(pose[1])
    msg.pose.pose.orientation.z = math.sin(0.5 * pose[2])
    msg.pose.pose.orientation.w = math.cos(0.5 * pose[2])
    msg.pose.covariance = _covariance6(pose_variance)
    msg.twist.twist.linear.x = float(twist[0])
    msg.twist.twist.linear.y = float(twist[1])
    msg.twist.twist.angular.z = float(twist[2])
    msg.twist.covariance = _covariance6(twist_variance)
    return msg


def _covariance6(planar: tuple[float, float, float]) -> NDArray[np.float64]:
    """Row-major 6x6 diagonal: x, y, yaw from ``planar``; z, roll, pitch a tiny fixed variance."""
    cov = np.zeros(36)
    cov[0], cov[7], cov[35] = planar
    cov[14] = cov[21] = cov[28] = 1e-9
    return cov


def static_transform(parent: str, child: str, xyz: tuple[float, float, float],
                     quaternion_xyzw: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 1.0)) -> Any:
    from aiorobot.msgs.geometry_msgs import TransformStamped

    t = TransformStamped()
    t.header.frame_id = parent
    t.child_frame_id = child
    t.transform.translation.x, t.transform.translation.y, t.transform.translation.z = (float(v) for v in xyz)
    q = t.transform.rotation
    q.x, q.y, q.z, q.w = (float(v) for v in quaternion_xyzw)
    return t


def occupancy_grid_message(world: Any, stamp: Any, frame_id: str = "map") -> Any:
    """``nav_msgs/OccupancyGrid`` of a :class:`~aiorobot.sim.World`."""
    from aiorobot.msgs.nav_msgs import OccupancyGrid

    msg = OccupancyGrid()
    msg.header.stamp = stamp
    msg.header.frame_id = frame_id
    msg.info.map_load_time = stamp
    msg.info.resolution = float(world.resolution)
    msg.info.height, msg.info.width = (int(v) for v in world.occupancy.shape)
    msg.info.origin.position.x = float(world.origin[0])
    msg.info.origin.position.y = float(world.origin[1])
    msg.info.origin.orientation.w = 1.0
    msg.data = np.ascontiguousarray(world.occupancy.reshape(-1), dtype=np.int8)
    return msg
