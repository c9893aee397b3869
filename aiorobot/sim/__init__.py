"""aiorobot.sim: a light 2D simulator — worlds, a mecanum or diff robot, lidar, IMU, odometry, camera.

Pure cores, usable without a runtime: :class:`World` (map_server YAML + image plus
ArUco landmarks; built-ins ``box`` and ``warehouse``), :func:`raycast` (Numba),
:class:`LidarModel`, :class:`ImuModel`, :class:`RobotBody`, :class:`CameraModel`,
:class:`MarkerRenderer`, :func:`project_landmark`, :func:`resolve_start` (the start pose, or the
free cell nearest the world's start when that is blocked, as on a Nav2 map).

The node: :class:`Simulator` (``use = "aiorobot.sim:Simulator"``).
"""

from __future__ import annotations

from ._builtin import CAMERA_HEIGHT_M, make_box, make_warehouse
from ._camera import OPTICAL_FROM_LINK, CameraModel, MarkerRenderer, camera_pose_matrix, project_landmark
from ._raycast import clearance_map, raycast
from ._robot import RobotBody, make_kinematics
from ._sensors import GRAVITY, ImuModel, LidarModel
from ._start import StartChoice, nearest_free_spot, parse_start, resolve_start
from ._simulator import CAMERA_XYZ, FRAMES, IMU_XYZ, LASER_XYZ, TIME_SOURCES, TOPICS, Simulator, SimulatorStatistics
from ._world import BUILTIN_WORLDS, Landmark, World, WorldError, builtin_world_path
from ._world_file import export_landmark_map, load_world, save_world

__all__ = [
    "BUILTIN_WORLDS",
    "CAMERA_HEIGHT_M",
    "CAMERA_XYZ",
    "CameraModel",
    "FRAMES",
    "GRAVITY",
    "IMU_XYZ",
    "ImuModel",
    "LASER_XYZ",
    "Landmark",
    "LidarModel",
    "MarkerRenderer",
    "OPTICAL_FROM_LINK",
    "RobotBody",
    "Simulator",
    "SimulatorStatistics",
    "StartChoice",
    "TIME_SOURCES",
    "TOPICS",
    "World",
    "WorldError",
    "builtin_world_path",
    "camera_pose_matrix",
    "clearance_map",
    "export_landmark_map",
    "load_world",
    "make_box",
    "make_kinematics",
    "make_warehouse",
    "nearest_free_spot",
    "parse_start",
    "project_landmark",
    "raycast",
    "resolve_start",
    "save_world",
]
