"""aiorobot.perception: kernels (ArUco, colour blobs, scans, clouds), a shared-memory frame ring, pipelines.

Pure kernels (numpy in, results out, no runtime): :func:`detect_markers`,
:func:`detect_blobs`, :func:`scan_to_points`, :func:`segment_scan`,
:func:`extract_obstacles`, :func:`voxel_downsample`. Heavy imports (cv2, numba)
happen on first use.
"""

from __future__ import annotations

from ._aruco import MarkerPose, detect_markers, marker_object_points
from ._images import ENCODINGS, BadInput, camera_matrix_from_info, image_array
from ._render import pinhole_matrix, render_markers

__all__ = [
    "ENCODINGS",
    "BadInput",
    "MarkerPose",
    "camera_matrix_from_info",
    "detect_markers",
    "image_array",
    "marker_object_points",
    "pinhole_matrix",
    "render_markers",
]
