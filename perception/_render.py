"""Render ArUco markers into a frame at known poses (a pinhole model): for tests, benchmarks and demos."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from ._aruco import marker_object_points

__all__ = ["draw_markers", "pinhole_matrix", "render_markers"]


def pinhole_matrix(fx: float = 500.0, fy: float = 500.0, cx: float = 320.0, cy: float = 240.0) -> NDArray[np.float64]:
    """A 3x3 camera matrix (the simulator's camera by default)."""
    return np.array([[fx, 0.0, cx], [0.0, fy, cy], [0.0, 0.0, 1.0]])


def render_markers(
    markers: Sequence[tuple[int, float, NDArray[np.float64], NDArray[np.float64]]],
    camera_matrix: NDArray[np.float64],
    size: tuple[int, int] = (640, 480),
    dictionary: int = 0,
    background: int = 128,
) -> NDArray[np.uint8]:
    """An RGB frame (H, W, 3) with each ``(id, length_m, rotation 3x3, translation 3)`` marker drawn.

    The marker's pixels (black border included) are warped with the homography
    its four corners project to; a white quiet zone of one cell surrounds it.
    """
    import cv2

    width, height = size
    frame = np.full((height, width), background, np.uint8)
    aruco_dict = cv2.aruco.getPredefinedDictionary(dictionary)
    cells = aruco_dict.markerSize + 2
    px = 40 * cells
    for marker_id, length, rotation, translation in markers:
        marker = cv2.aruco.generateImageMarker(aruco_dict, int(marker_id), px, borderBits=1)
        pad = px // cells
        tile = np.full((px + 2 * pad, px + 2 * pad), 255, np.uint8)
        tile[pad:pad + px, pad:pad + px] = marker
        scale = (px + 2 * pad) / px
        corners3d = marker_object_points(length * scale) @ np.asarray(rotation).T + np.asarray(translation)
        projected = corners3d @ camera_matrix.T
        projected = (projected[:, :2] / projected[:, 2:3]).astype(np.float32)
        n = float(tile.shape[0])
        source = np.array([[0, 0], [n, 0], [n, n], [0, n]], np.float32)
        homography = cv2.getPerspectiveTransform(source, projected)
        warped = cv2.warpPerspective(tile, homography, (width, height), flags=cv2.INTER_LINEAR, borderValue=0)
        mask = cv2.warpPerspective(np.ones_like(tile), homography, (width, height), flags=cv2.INTER_NEAREST)
        frame[mask > 0] = warped[mask > 0]
    return np.ascontiguousarray(np.repeat(frame[:, :, None], 3, axis=2))


def draw_markers(
    image: NDArray[np.uint8],
    markers: Sequence[object],
    camera_matrix: NDArray[np.float64],
    marker_length: float,
) -> NDArray[np.uint8]:
    """A copy of an RGB ``image`` with each :class:`MarkerPose`'s outline, id and pose axes drawn."""
    import cv2

    out = np.ascontiguousarray(image.copy())
    for marker in markers:
        corners = np.asarray(marker.corners, np.float32).reshape(1, 4, 2)  # type: ignore[attr-defined]
        cv2.aruco.drawDetectedMarkers(out, [corners], np.array([[marker.marker_id]]),  # type: ignore[attr-defined]
                                      borderColor=(0, 255, 0))
        cv2.drawFrameAxes(out, camera_matrix, np.zeros(5), marker.rvec, marker.tvec,  # type: ignore[attr-defined]
                          marker_length / 2, 3)
    return out
