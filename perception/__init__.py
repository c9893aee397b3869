"""aiorobot.perception: kernels (ArUco, colour blobs, scans, clouds), a shared-memory frame ring, pipelines.

Pure kernels (numpy in, results out, no runtime): :func:`detect_markers`,
:func:`detect_blobs`, :func:`scan_to_points`, :func:`segment_scan`,
:func:`extract_obstacles`, :func:`voxel_downsample`. Heavy imports (cv2, numba)
happen on first use.
"""

from __future__ import annotations

from ._aruco import MarkerPose, detect_markers, marker_object_points
from ._aruco_node import ArucoNode, PipelineNode, aruco_kernel, declare_pipeline_parameters, markers_message
from ._blobs import Blob, detect_blobs
from ._cloud import cloud_to_xyz, voxel_downsample, xyz_to_cloud
from ._detection_map import DetectionMap, DetectionMapNode, MapMarker
from ._images import ENCODINGS, BadInput, camera_matrix_from_info, image_array
from ._msgs import MarkerDetection, MarkerDetectionArray
from ._pipeline import POLICIES, Pipeline, PipelineStatistics, StageLatency
from ._render import draw_markers, pinhole_matrix, render_markers
from ._ring import FrameRing, RingAttachment
from ._scan import extract_obstacles, scan_to_points, segment_scan
from ._scan_node import ScanObstacleNode, scan_obstacles
from ._worker import Frame

__all__ = [
    "ENCODINGS",
    "POLICIES",
    "ArucoNode",
    "BadInput",
    "Blob",
    "DetectionMap",
    "DetectionMapNode",
    "Frame",
    "FrameRing",
    "MapMarker",
    "MarkerDetection",
    "MarkerDetectionArray",
    "MarkerPose",
    "Pipeline",
    "PipelineNode",
    "PipelineStatistics",
    "RingAttachment",
    "ScanObstacleNode",
    "StageLatency",
    "annotations",
    "aruco_kernel",
    "camera_matrix_from_info",
    "cloud_to_xyz",
    "declare_pipeline_parameters",
    "detect_blobs",
    "draw_markers",
    "detect_markers",
    "extract_obstacles",
    "image_array",
    "marker_object_points",
    "markers_message",
    "pinhole_matrix",
    "render_markers",
    "scan_obstacles",
    "scan_to_points",
    "segment_scan",
    "voxel_downsample",
    "xyz_to_cloud",
]
