"""ArUco marker detection with pose: a pure function on a numpy image (OpenCV, releases the GIL)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = ["MarkerPose", "detect_markers", "marker_object_points"]


@dataclass(frozen=True)
class MarkerPose:
    """One detected marker: id, pose of the marker in the camera optical frame, corner pixels.

    ``rvec``/``tvec`` are OpenCV's Rodrigues vector and translation (metres), so
    ``camera_from_marker = [R(rvec) | tvec]``. ``corners`` is (4, 2): top-left,
    top-right, bottom-right, bottom-left in pixels.
    """

    marker_id: int
    rvec: NDArray[np.float64]
    tvec: NDArray[np.float64]
    corners: NDArray[np.float64]


def marker_object_points(marker_length: float) -> NDArray[np.float64]:
    """The four corners of a square marker in its own frame (z=0), in IPPE_SQUARE's order."""
    h = marker_length / 2.0
    return np.array([[-h, h, 0.0], [h, h, 0.0], [h, -h, 0.0], [-h, -h, 0.0]])


_detectors: dict[int, Any] = {}


def _detector(dictionary: int) -> Any:
    import cv2

    detector = _detectors.get(dictionary)
    if detector is None:
        params = cv2.aruco.DetectorParameters()
        params.cornerRefinementMethod = cv2.aruco.CORNER_REFINE_SUBPIX
        detector = cv2.aruco.ArucoDetector(cv2.aruco.getPredefinedDictionary(dictionary), params)
        _detectors[dictionary] = detector
    return detector


def detect_markers(
    image: NDArray[np.uint8],
    camera_matrix: NDArray[np.float64],
    dist_coeffs: NDArray[np.float64] | None,
    marker_length: float,
    dictionary: int = 0,
) -> list[MarkerPose]:
    """Find ArUco markers in ``image`` ((H, W) or (H, W, 3) uint8) and solve each one's pose.

    ``dictionary`` is an OpenCV predefined dictionary id (0 = ``DICT_4X4_50``);
    ``marker_length`` is the side of the black square in metres. Markers are
    returned sorted by id.
    """
    import cv2

    gray = image if image.ndim == 2 else cv2.cvtColor(image, cv2.COLOR_RGB2GRAY)
    corners, ids, _ = _detector(dictionary).detectMarkers(gray)
    if ids is None:
        return []
    objects = marker_object_points(marker_length)
    dist = np.zeros(5) if dist_coeffs is None else np.asarray(dist_coeffs, dtype=np.float64)
    found = []
    for marker_corners, marker_id in zip(corners, ids.ravel()):
        pixels = np.asarray(marker_corners, dtype=np.float64).reshape(4, 2)
        ok, rvec, tvec = cv2.solvePnP(objects, pixels, camera_matrix, dist, flags=cv2.SOLVEPNP_IPPE_SQUARE)
        if ok:
            found.append(MarkerPose(int(marker_id), rvec.ravel(), tvec.ravel(), pixels))
    return sorted(found, key=lambda m: m.marker_id)
