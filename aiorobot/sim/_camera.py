"""A pinhole camera that sees ArUco landmarks: projection and rendering with OpenCV.

Frames (REP 103): ``camera_link`` looks along +x with z up; ``camera_optical_frame``
has z forward, x right, y down, as OpenCV and ``sensor_msgs/CameraInfo`` expect.
Pixel coordinates follow OpenCV: the centre of pixel ``(u, v)`` is at ``(u, v)``.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ._world import Landmark

__all__ = [
    "CameraModel",
    "MarkerRenderer",
    "OPTICAL_FROM_LINK",
    "camera_pose_matrix",
    "project_landmark",
]

#: Rotation taking camera_link vectors to camera_optical_frame vectors.
OPTICAL_FROM_LINK = np.array([[0.0, -1.0, 0.0], [0.0, 0.0, -1.0], [1.0, 0.0, 0.0]])
#: Nearest depth (m) a marker corner may have and still be drawn.
_NEAR_M = 0.05


@dataclass(frozen=True, slots=True)
class CameraModel:
    """Pinhole intrinsics without distortion (``sensor_msgs/CameraInfo``'s ``plumb_bob`` with zero D)."""

    width: int = 640
    height: int = 480
    fx: float = 500.0
    fy: float = 500.0
    cx: float = 320.0
    cy: float = 240.0

    def __post_init__(self) -> None:
        for name in ("width", "height"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int) or value <= 0:
                raise ValueError(f"camera {name}: expected an int > 0 pixels, found {value!r}")
        for name in ("fx", "fy"):
            if not getattr(self, name) > 0:
                raise ValueError(f"camera {name}: expected a focal length > 0 pixels, found {getattr(self, name)!r}")

    @property
    def K(self) -> NDArray[np.float64]:  # noqa: N802 - the conventional name
        """The 3x3 camera matrix."""
        return np.array([[self.fx, 0.0, self.cx], [0.0, self.fy, self.cy], [0.0, 0.0, 1.0]])

    def project(self, points_optical: ArrayLike) -> NDArray[np.float64]:
        """``(n, 3)`` points in the optical frame -> ``(n, 2)`` pixel coordinates (z must be > 0)."""
        p = np.asarray(points_optical, dtype=np.float64)
        if p.ndim != 2 or p.shape[1] != 3:
            raise ValueError(f"points_optical must have shape (n, 3), got shape {p.shape}")
        z = p[:, 2]
        return np.stack([self.fx * p[:, 0] / z + self.cx, self.fy * p[:, 1] / z + self.cy], axis=1)


def camera_pose_matrix(x: float, y: float, z: float, yaw: float) -> NDArray[np.float64]:
    """``map_from_optical``: the 4x4 pose of the optical frame of a level camera_link at ``(x, y, z, yaw)``."""
    c, s = math.cos(yaw), math.sin(yaw)
    map_from_link = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    pose = np.eye(4)
    pose[:3, :3] = map_from_link @ OPTICAL_FROM_LINK.T
    pose[:3, 3] = (x, y, z)
    return pose


def _to_optical(points_map: NDArray[np.float64], map_from_optical: NDArray[np.float64]) -> NDArray[np.float64]:
    rotation = map_from_optical[:3, :3]
    return (points_map - map_from_optical[:3, 3]) @ rotation


def project_landmark(
    landmark: Landmark, map_from_optical: ArrayLike, camera: CameraModel
) -> NDArray[np.float64] | None:
    """Pixel corners ``(4, 2)`` of ``landmark`` in ArUco order, or None when behind the camera or seen from behind."""
    pose = np.asarray(map_from_optical, dtype=np.float64)
    if pose.shape != (4, 4):
        raise ValueError(f"map_from_optical must have shape (4, 4), got shape {pose.shape}")
    if not _faces(landmark, pose[:3, 3]):
        return None
    corners = _to_optical(landmark.corners(), pose)
    if np.any(corners[:, 2] < _NEAR_M):
        return None
    return camera.project(corners)


def _faces(landmark: Landmark, camera_position: NDArray[np.float64]) -> bool:
    normal = (math.cos(landmark.yaw), math.sin(landmark.yaw))
    return (camera_position[0] - landmark.x) * normal[0] + (camera_position[1] - landmark.y) * normal[1] > 1e-9


class MarkerRenderer:
    """Draws landmarks into RGB images with a correct pinhole projection.

    Each marker is drawn with a one-cell white quiet zone around its black border,
    warped by the homography of its four projected corners (``cv2.warpPerspective``
    on the marker's bounding box only). Markers are painted far to near.

    Parameters
    ----------
    landmarks : sequence of Landmark
    camera : CameraModel
    pixels_per_cell : int
        Texture resolution: pixels per ArUco bit cell.
    """

    def __init__(self, landmarks: Sequence[Landmark], camera: CameraModel, *, pixels_per_cell: int = 16) -> None:
        import cv2

        self.camera = camera
        self.landmarks = tuple(landmarks)
        self._textures: list[NDArray[np.uint8]] = []
        self._margins: list[float] = []
        for lm in self.landmarks:
            dictionary = cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, lm.dictionary))
            cells = dictionary.markerSize + 2  # bits plus the black border
            marker = cv2.aruco.generateImageMarker(dictionary, lm.id, cells * pixels_per_cell, borderBits=1)
            padded = cv2.copyMakeBorder(marker, pixels_per_cell, pixels_per_cell, pixels_per_cell, pixels_per_cell,
                                        cv2.BORDER_CONSTANT, value=255)
            self._textures.append(np.ascontiguousarray(np.repeat(padded[:, :, None], 3, axis=2)))
            self._margins.append(lm.size / cells)
        self._all_corners = np.array(
            [lm.corners_with_margin(m) for lm, m in zip(self.landmarks, self._margins)]
        ).reshape(-1, 4, 3)
        self._centres = np.array([(lm.x, lm.y) for lm in self.landmarks]).reshape(-1, 2)
        self._normals = np.array([(math.cos(lm.yaw), math.sin(lm.yaw)) for lm in self.landmarks]).reshape(-1, 2)
        self._background: NDArray[np.uint8] | None = None

    def __repr__(self) -> str:
        return f"<MarkerRenderer {len(self.landmarks)} markers {self.camera.width}x{self.camera.height}>"

    def background(self) -> NDArray[np.uint8]:
        """A plain scene: wall grey above the horizon, floor below (shape (height, width, 3), rgb8)."""
        if self._background is None:
            cam = self.camera
            image = np.empty((cam.height, cam.width, 3), dtype=np.uint8)
            horizon = int(min(max(round(cam.cy), 0), cam.height))
            image[:horizon] = (176, 172, 166)
            image[horizon:] = (96, 90, 84)
            self._background = image
        return self._background

    def render(
        self,
        map_from_optical: ArrayLike,
        *,
        image: NDArray[np.uint8] | None = None,
        visible: Callable[[Landmark, NDArray[np.float64]], bool] | None = None,
    ) -> tuple[NDArray[np.uint8], list[int]]:
        """Render the markers seen from ``map_from_optical`` (4x4).

        ``visible(landmark, camera_position)`` may veto a marker (occlusion by walls).
        Returns the image (``image`` filled in place if given) and the ids drawn.
        """
        import cv2

        pose = np.asarray(map_from_optical, dtype=np.float64)
        cam = self.camera
        if image is None:
            image = self.background().copy()
        else:
            np.copyto(image, self.background())
        position = pose[:3, 3]
        facing = (position[0] - self._centres[:, 0]) * self._normals[:, 0] + (
            position[1] - self._centres[:, 1]
        ) * self._normals[:, 1] > 1e-9
        ids: list[int] = []
        candidates = np.flatnonzero(facing)
        if candidates.size == 0:
            return image, ids
        optical = (self._all_corners[candidates] - position) @ pose[:3, :3]  # (k, 4, 3)
        in_front = np.all(optical[:, :, 2] >= _NEAR_M, axis=1)
        candidates, optical = candidates[in_front], optical[in_front]
        z = optical[:, :, 2]
        pixels_all = np.stack([cam.fx * optical[:, :, 0] / z + cam.cx, cam.fy * optical[:, :, 1] / z + cam.cy], axis=2)
        order = np.argsort(-z.mean(axis=1), kind="stable")  # far to near
        for k in order:
            index = int(candidates[k])
            lm = self.landmarks[index]
            pixels = pixels_all[k]
            x0 = max(int(math.floor(pixels[:, 0].min())), 0)
            y0 = max(int(math.floor(pixels[:, 1].min())), 0)
            x1 = min(int(math.ceil(pixels[:, 0].max())) + 1, cam.width)
            y1 = min(int(math.ceil(pixels[:, 1].max())) + 1, cam.height)
            if x0 >= x1 or y0 >= y1:
                continue
            if visible is not None and not visible(lm, position):
                continue
            texture = self._textures[index]
            side = texture.shape[0]
            # texture pixel edges are at -0.5 and side - 0.5 in OpenCV's centre-of-pixel convention
            src = np.array([[-0.5, -0.5], [side - 0.5, -0.5], [side - 0.5, side - 0.5], [-0.5, side - 0.5]],
                           dtype=np.float32)
            dst = (pixels - (x0, y0)).astype(np.float32)
            homography = cv2.getPerspectiveTransform(src, dst)
            roi = image[y0:y1, x0:x1]
            cv2.warpPerspective(texture, homography, (x1 - x0, y1 - y0), dst=roi, flags=cv2.INTER_LINEAR,
                                borderMode=cv2.BORDER_TRANSPARENT)
            ids.append(lm.id)
        return image, ids
