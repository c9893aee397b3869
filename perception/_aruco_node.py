"""Nodes around a :class:`Pipeline`: one sized by parameters, and the ArUco detector node."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from aiorobot import Node

from ._aruco import detect_markers
from ._images import BadInput, camera_matrix_from_info
from ._msgs import MarkerDetection, MarkerDetectionArray
from ._pipeline import Pipeline
from ._worker import Frame

__all__ = ["ArucoNode", "PipelineNode", "aruco_kernel", "declare_pipeline_parameters", "markers_message"]


def declare_pipeline_parameters(node: Any) -> dict[str, Any]:
    """Declare ``workers``, ``queue`` and ``policy`` on ``node``; returns them as Pipeline keywords."""
    return {
        "workers": node.declare_parameter("workers", 1, description="worker processes").value,
        "queue": node.declare_parameter("queue", 1, description="frames that may wait for a worker").value,
        "policy": node.declare_parameter("policy", "latest", description="'latest' or 'drop_oldest'").value,
    }


class PipelineNode(Node):
    """A node that is one pipeline, sized by its parameters ``workers``, ``queue`` and ``policy``.

    ``PipelineNode("blobs", "/camera/image_raw", Image, my_kernel, publish=("/blobs", PoseArray))``
    """

    def __init__(
        self,
        name: str,
        topic: str,
        msg_type: type,
        kernel: Callable[[Any, Frame], Any],
        *,
        publish: tuple[str, type] | None = None,
        context: Callable[[], Any] | None = None,
        **node_kwargs: Any,
    ) -> None:
        super().__init__(name, **node_kwargs)
        self.pipeline = Pipeline(self, topic, msg_type, kernel, publish=publish, context=context,
                                 **declare_pipeline_parameters(self))

    async def on_start(self) -> None:
        await self.pipeline.start()

    async def on_shutdown(self) -> None:
        await self.pipeline.close()


def markers_message(markers: list[Any], header: Any, marker_length: float) -> Any:
    """A ``MarkerDetectionArray`` from :func:`detect_markers`' result."""
    import cv2

    from aiorobot.tf import quaternion_from_matrix

    out = MarkerDetectionArray()
    if header is not None:
        out.header = header
    for marker in markers:
        d = MarkerDetection(marker_id=marker.marker_id, marker_length=marker_length)
        d.pose.position.x, d.pose.position.y, d.pose.position.z = (float(v) for v in marker.tvec)
        rotation, _ = cv2.Rodrigues(marker.rvec)
        q = quaternion_from_matrix(rotation)
        d.pose.orientation.x, d.pose.orientation.y, d.pose.orientation.z, d.pose.orientation.w = (float(v) for v in q)
        d.corners = marker.corners.astype(np.float32).ravel()
        out.detections.append(d)
    return out


def aruco_kernel(pixels: Any, frame: Frame) -> Any:
    """Pipeline kernel: ArUco markers with pose; ``frame.context`` is ``(K, D, marker_length, dictionary)``."""
    import cv2

    k, d, marker_length, dictionary = frame.context
    if frame.encoding == "bgr8":
        gray = cv2.cvtColor(pixels, cv2.COLOR_BGR2GRAY)
    elif frame.encoding == "rgb8":
        gray = cv2.cvtColor(pixels, cv2.COLOR_RGB2GRAY)
    elif frame.encoding == "mono8":
        gray = pixels[:, :, 0]
    else:
        raise BadInput(f"the ArUco kernel reads rgb8, bgr8 or mono8 images, got {frame.encoding!r}")
    markers = detect_markers(gray, np.asarray(k), np.asarray(d), marker_length, dictionary)
    return markers_message(markers, frame.header, marker_length)


class ArucoNode(Node):
    """ArUco markers with pose in the camera optical frame, from an image and its CameraInfo.

    Parameters: ``image_topic`` (/camera/image_raw), ``camera_info_topic``
    (/camera/camera_info), ``detections_topic`` (/detections/markers),
    ``marker_length`` (metres, 0.5), ``dictionary`` (OpenCV name, DICT_4X4_50),
    plus ``workers``, ``queue``, ``policy``. Frames before the first CameraInfo
    are dropped, counted and warned about.
    """

    def __init__(self, name: str = "aruco", **node_kwargs: Any) -> None:
        import cv2

        from aiorobot.msgs.sensor_msgs import CameraInfo, Image

        super().__init__(name, **node_kwargs)
        image_topic = self.declare_parameter("image_topic", "/camera/image_raw", read_only=True).value
        info_topic = self.declare_parameter("camera_info_topic", "/camera/camera_info", read_only=True).value
        out_topic = self.declare_parameter("detections_topic", "/detections/markers", read_only=True).value
        self.marker_length = float(self.declare_parameter("marker_length", 0.5).value)
        dictionary_name = self.declare_parameter("dictionary", "DICT_4X4_50").value
        if not dictionary_name.startswith("DICT_") or not hasattr(cv2.aruco, dictionary_name):
            raise ValueError(f"dictionary: expected an OpenCV ArUco dictionary name like 'DICT_4X4_50', "
                             f"got {dictionary_name!r}")
        self.dictionary = int(getattr(cv2.aruco, dictionary_name))
        self.info_topic = info_topic
        self._camera: tuple[Any, Any] | None = None
        self.create_subscription(CameraInfo, info_topic, self._on_info, 10)
        self.pipeline = Pipeline(self, image_topic, Image, aruco_kernel, publish=(out_topic, MarkerDetectionArray),
                                 context=self._context, **declare_pipeline_parameters(self))

    async def on_start(self) -> None:
        await self.pipeline.start()

    async def on_shutdown(self) -> None:
        await self.pipeline.close()

    def _on_info(self, info: Any) -> None:
        try:
            k, d = camera_matrix_from_info(info)
        except BadInput as exc:
            self.get_logger().warning(f"{self.info_topic}: {exc}", throttle_duration_sec=5.0)
            return
        self._camera = (k, d)

    def _context(self) -> Any:
        if self._camera is None:
            raise BadInput(f"no camera_info received on {self.info_topic} yet")
        k, d = self._camera
        return (k, d, self.marker_length, self.dictionary)
