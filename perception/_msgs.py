"""The detection messages, registered from .msg text as ``aiorobot_msgs`` types (see docs/perception.md)."""

from __future__ import annotations

from aiorobot import msgs

__all__ = ["MARKER_DETECTION_ARRAY_MSG", "MARKER_DETECTION_MSG", "MarkerDetection", "MarkerDetectionArray"]

MARKER_DETECTION_MSG = """\
# One ArUco marker seen by a camera.
int32 marker_id
float64 marker_length            # side of the black square, metres
geometry_msgs/Pose pose          # marker centre and orientation in the header's frame (camera optical frame)
float32[8] corners               # pixels x0 y0 x1 y1 x2 y2 x3 y3: top-left, top-right, bottom-right, bottom-left
"""

MARKER_DETECTION_ARRAY_MSG = """\
# Every marker found in one image; the header is the image's (stamp and camera optical frame).
std_msgs/Header header
aiorobot_msgs/MarkerDetection[] detections
"""

MarkerDetection = msgs.register_msg(MARKER_DETECTION_MSG, "aiorobot_msgs/msg/MarkerDetection")
MarkerDetectionArray = msgs.register_msg(MARKER_DETECTION_ARRAY_MSG, "aiorobot_msgs/msg/MarkerDetectionArray")
