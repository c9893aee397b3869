"""Landmark fixes: the robot's pose in the map from one ArUco marker at a known place.

:func:`base_pose_from_marker` is the pure core (4x4 transforms on numpy); :class:`LandmarkFixNode`
turns perception's ``/detections/markers`` into ``/landmark_pose``
(``geometry_msgs/PoseWithCovarianceStamped`` of ``base_link`` in ``map``, at the image's stamp),
the absolute input of the fusion package's map-frame EKF (``pose0`` of robot_localization's
dual-EKF set-up, see ``examples/fusion_ekf.toml``).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .._core._node import Node

__all__ = ["LandmarkFixNode", "base_pose_from_marker", "base_pose_from_markers", "map_from_marker"]


def map_from_marker(x: float, y: float, z: float, yaw: float) -> NDArray[np.float64]:
    """The (4, 4) pose of a wall marker's ArUco frame in the map.

    ArUco's marker frame has x to the right and y up as a viewer facing the marker sees it,
    and z out of the marker towards the viewer; the marker's outward normal points along ``yaw``.
    """
    c, s = math.cos(yaw), math.sin(yaw)
    pose = np.eye(4)
    pose[:3, 0] = (-s, c, 0.0)   # right, seen from the front
    pose[:3, 1] = (0.0, 0.0, 1.0)  # up
    pose[:3, 2] = (c, s, 0.0)    # the outward normal
    pose[:3, 3] = (x, y, z)
    return pose


def base_pose_from_marker(
    map_from_marker_: NDArray[np.float64],
    optical_from_marker: NDArray[np.float64],
    base_from_optical: NDArray[np.float64],
    yaw: float | None = None,
) -> tuple[float, float, float]:
    """``(x, y, yaw)`` of the base in the map, from one marker seen by the camera.

    With ``yaw`` given (the filter's current heading), only the marker's position is used:
    the base is placed so that the marker appears where it was seen, at that heading. A
    small marker's position is accurate to centimetres, its orientation is not (solvePnP's
    two-fold ambiguity flips it by tenths of a radian), so fixes take their heading from
    the filter and correct position only.

    Parameters
    ----------
    map_from_marker_ : (4, 4)
        Where the marker is (:func:`map_from_marker`).
    optical_from_marker : (4, 4)
        The detected marker pose in the camera optical frame (ArUco's rvec/tvec).
    base_from_optical : (4, 4)
        The camera optical frame on the base (tf base_link -> camera_optical_frame).
    yaw : float, optional
        The base's heading in the map; when None it comes from the marker's orientation.
    """
    a = np.asarray(map_from_marker_, dtype=np.float64)
    b = np.asarray(optical_from_marker, dtype=np.float64)
    c = np.asarray(base_from_optical, dtype=np.float64)
    for name, m in (("map_from_marker", a), ("optical_from_marker", b), ("base_from_optical", c)):
        if m.shape != (4, 4):
            raise ValueError(f"{name} must have shape (4, 4), got shape {m.shape}")
    if yaw is not None:
        marker_in_base = c @ b[:, 3]
        cy, sy = math.cos(yaw), math.sin(yaw)
        x = a[0, 3] - (cy * marker_in_base[0] - sy * marker_in_base[1])
        y = a[1, 3] - (sy * marker_in_base[0] + cy * marker_in_base[1])
        return float(x), float(y), float(yaw)
    map_from_base = a @ np.linalg.inv(b) @ np.linalg.inv(c)
    return float(map_from_base[0, 3]), float(map_from_base[1, 3]), math.atan2(map_from_base[1, 0], map_from_base[0, 0])


def base_pose_from_markers(
    map_from_markers: list[NDArray[np.float64]],
    optical_from_markers: list[NDArray[np.float64]],
    base_from_optical: NDArray[np.float64],
) -> tuple[float, float, float]:
    """``(x, y, yaw)`` of the base in the map from two or more markers seen in one image.

    Uses the markers' positions only (accurate to centimetres, where a small marker's
    orientation is not): the 2-D rigid transform that best lays the markers' positions on the
    base onto their places in the map, in the least-squares sense (Kabsch). Its heading is as
    good as the markers are far apart.
    """
    if len(map_from_markers) != len(optical_from_markers) or len(map_from_markers) < 2:
        raise ValueError(
            f"base_pose_from_markers: expected two or more (map_from_marker, optical_from_marker) pairs, "
            f"found {len(map_from_markers)} and {len(optical_from_markers)}"
        )
    c = np.asarray(base_from_optical, dtype=np.float64)
    if c.shape != (4, 4):
        raise ValueError(f"base_from_optical must have shape (4, 4), got shape {c.shape}")
    in_map = np.array([np.asarray(a, dtype=np.float64)[:2, 3] for a in map_from_markers])
    in_base = np.array([(c @ np.asarray(b, dtype=np.float64)[:, 3])[:2] for b in optical_from_markers])
    pm, pb = in_map - in_map.mean(axis=0), in_base - in_base.mean(axis=0)
    # the rotation taking base-frame offsets onto map-frame ones: atan2(sum of cross, sum of dot)
    yaw = math.atan2(float(np.sum(pb[:, 0] * pm[:, 1] - pb[:, 1] * pm[:, 0])), float(np.sum(pb[:, 0] * pm[:, 0] + pb[:, 1] * pm[:, 1])))
    cy, sy = math.cos(yaw), math.sin(yaw)
    mb = in_base.mean(axis=0)
    mm = in_map.mean(axis=0)
    return float(mm[0] - (cy * mb[0] - sy * mb[1])), float(mm[1] - (sy * mb[0] + cy * mb[1])), yaw


class LandmarkFixNode(Node):
    """``/detections/markers`` (aiorobot_msgs/MarkerDetectionArray) -> ``/landmark_pose``.

    Parameters: ``landmark_map`` (the landmark map file saying where each marker id is, see
    :func:`~aiorobot.nav.load_landmark_map`; a simulator world's is beside its map YAML,
    :func:`~aiorobot.nav.landmark_map_path`), ``markers_topic`` (/detections/markers), ``pose_topic`` (/landmark_pose),
    ``map_frame`` (map), ``base_frame`` (base_link), ``max_range_m`` (4.0: farther markers are
    ignored), ``position_std_m`` (0.03 at 1 m, growing with the square of the range) and
    ``yaw_std_rad`` (0.05: the heading's uncertainty, whose effect on position grows with the
    range). An image with two or more known markers at least ``min_baseline_m`` (1.0) apart
    gives one fix of the whole pose, heading included, from the markers' positions
    (:func:`base_pose_from_markers`; yaw standard deviation = the position's times sqrt(2) over
    the markers' spread). Otherwise each marker gives a fix of position only: its heading is the
    current map -> base_link estimate's (tf at the image's stamp; see
    :func:`base_pose_from_marker`) and carries a variance of 1e6, so a filter that fuses the
    fix's yaw (``pose0_config`` x, y and yaw) takes heading only from the multi-marker fixes.
    Unknown ids, markers beyond range and frames without a heading estimate yet are counted in
    ``ignored``; ``heading_fixes`` counts the fixes that measured the heading.
    """

    def __init__(self, node_name: str = "landmark_fixes", **kwargs: Any) -> None:
        super().__init__(node_name, **kwargs)
        from aiorobot.msgs.geometry_msgs import PoseWithCovarianceStamped
        from aiorobot.perception import MarkerDetectionArray
        from aiorobot.tf import Buffer, TransformListener

        from ._landmark_map import load_landmark_map

        d = self.declare_parameter
        path = str(d("landmark_map", "", read_only=True).value)
        if not path:
            raise ValueError("parameter landmark_map: expected the path of a landmark map file "
                             "(such as a simulator world's <map>.landmarks.yaml), found ''")
        #: where the markers are (a :class:`~aiorobot.nav.LandmarkMap`)
        self.landmark_map = load_landmark_map(path)
        markers_topic = str(d("markers_topic", "/detections/markers", read_only=True).value)
        pose_topic = str(d("pose_topic", "/landmark_pose", read_only=True).value)
        self.map_frame = str(d("map_frame", "map").value)
        self.base_frame = str(d("base_frame", "base_link").value)
        if self.landmark_map.frame_id != self.map_frame:
            raise ValueError(f"{path}: frame_id: expected the map frame {self.map_frame!r} (parameter map_frame), "
                             f"found {self.landmark_map.frame_id!r}")
        self.max_range_m = float(d("max_range_m", 4.0).value)
        self.position_std_m = float(d("position_std_m", 0.03).value)
        self.yaw_std_rad = float(d("yaw_std_rad", 0.05).value)
        self.min_baseline_m = float(d("min_baseline_m", 1.0).value)
        self.landmarks = {i: m.map_from_marker() for i, m in self.landmark_map.markers.items()}
        self.fixes = 0
        self.heading_fixes = 0
        self.ignored = 0
        self.buffer = Buffer()
        self.listener = TransformListener(self.buffer, self)
        self.pub = self.create_publisher(PoseWithCovarianceStamped, pose_topic, 10)
        self.create_subscription(MarkerDetectionArray, markers_topic, self.on_markers, 10)
        self._msg_type = PoseWithCovarianceStamped
        self._base_from_optical: dict[str, NDArray[np.float64]] = {}

    def __repr__(self) -> str:
        return (f"<LandmarkFixNode landmarks={len(self.landmarks)} fixes={self.fixes} "
                f"heading_fixes={self.heading_fixes} ignored={self.ignored}>")

    def _mount(self, frame: str) -> NDArray[np.float64] | None:
        from aiorobot import Time
        from aiorobot.tf import TransformException, transform_from_pq

        if frame not in self._base_from_optical:
            try:
                t = self.buffer.lookup_transform(self.base_frame, frame, Time()).transform
            except TransformException as err:
                self.get_logger().warning(f"no {self.base_frame} -> {frame} yet: {err}", throttle_duration_sec=5.0)
                return None
            self._base_from_optical[frame] = transform_from_pq(
                (t.translation.x, t.translation.y, t.translation.z),
                (t.rotation.x, t.rotation.y, t.rotation.z, t.rotation.w))
        return self._base_from_optical[frame]

    def _heading(self, stamp: Any) -> float | None:
        from aiorobot import Time
        from aiorobot.tf import TransformException

        from ._geometry import transform_to_xyyaw

        for when in (Time.from_msg(stamp), Time()):
            try:
                return transform_to_xyyaw(self.buffer.lookup_transform(self.map_frame, self.base_frame, when))[2]
            except TransformException:
                continue
        return None

    def on_markers(self, msg: Any) -> None:
        from aiorobot.tf import transform_from_pq

        if not msg.detections:
            return
        mount = self._mount(msg.header.frame_id)
        if mount is None:
            self.ignored += len(msg.detections)
            return
        seen: list[tuple[NDArray[np.float64], NDArray[np.float64], float]] = []
        for det in msg.detections:
            where = self.landmarks.get(int(det.marker_id))
            p, q = det.pose.position, det.pose.orientation
            distance = math.sqrt(p.x * p.x + p.y * p.y + p.z * p.z)
            if where is None or not distance <= self.max_range_m:
                self.ignored += 1
                continue
            seen.append((where, transform_from_pq((p.x, p.y, p.z), (q.x, q.y, q.z, q.w)), distance))
        if len(seen) >= 2:
            places = np.array([w[:2, 3] for w, _, _ in seen])
            spread = float(np.max(np.linalg.norm(places[:, None, :] - places[None, :, :], axis=2)))
            if spread >= self.min_baseline_m:
                x, y, yaw = base_pose_from_markers([w for w, _, _ in seen], [o for _, o, _ in seen], mount)
                far = max(dist for _, _, dist in seen)
                var_xy = (self.position_std_m * max(far, 1.0) ** 2) ** 2 / len(seen)
                self._publish(msg.header.stamp, x, y, yaw, var_xy, 2.0 * var_xy / spread ** 2)
                self.heading_fixes += 1
                return
        heading = self._heading(msg.header.stamp)
        if heading is None:
            self.ignored += len(seen)
            return
        for where, optical_from_marker, distance in seen:
            x, y, yaw = base_pose_from_marker(where, optical_from_marker, mount, yaw=heading)
            var_xy = (self.position_std_m * max(distance, 1.0) ** 2) ** 2 + (distance * self.yaw_std_rad) ** 2
            self._publish(msg.header.stamp, x, y, yaw, var_xy, 1e6)

    def _publish(self, stamp: Any, x: float, y: float, yaw: float, var_xy: float, var_yaw: float) -> None:
        from ._geometry import yaw_quaternion

        out = self._msg_type()
        out.header.stamp = stamp
        out.header.frame_id = self.map_frame
        out.pose.pose.position.x, out.pose.pose.position.y = x, y
        out.pose.pose.orientation = yaw_quaternion(yaw)
        cov = np.zeros(36)
        cov[0] = cov[7] = var_xy
        cov[14] = cov[21] = cov[28] = 1e6
        cov[35] = var_yaw
        out.pose.covariance = cov
        self.pub.publish(out)
        self.fixes += 1
