"""A stand-in for the simulator's sensors (``aiorobot.sim``), for examples/perception.toml.

Publishes what the simulator will, with the same names: ``/camera/image_raw``
(rgb8 640x480, four ArUco markers rendered at known poses with a pinhole model),
``/camera/camera_info`` (fx = fy = 500, cx = 320, cy = 240), ``/scan`` (360 beams
seeing two round obstacles inside a round room), and static tf
``map -> base_link -> camera_optical_frame, laser``.
"""

from __future__ import annotations

import math

import numpy as np

from aiorobot import Node
from aiorobot.msgs.geometry_msgs import TransformStamped
from aiorobot.msgs.sensor_msgs import CameraInfo, Image, LaserScan
from aiorobot.perception import pinhole_matrix, render_markers
from aiorobot.tf import StaticTransformBroadcaster

__all__ = ["DemoSensors"]

FACING = np.diag([1.0, -1.0, -1.0])
OPTICAL = (-0.5, 0.5, -0.5, 0.5)  # camera optical frame (z forward, x right, y down) in base_link


def _static(parent: str, child: str, xyz: tuple[float, float, float], q: tuple[float, ...]) -> TransformStamped:
    t = TransformStamped()
    t.header.frame_id, t.child_frame_id = parent, child
    t.transform.translation.x, t.transform.translation.y, t.transform.translation.z = xyz
    t.transform.rotation.x, t.transform.rotation.y, t.transform.rotation.z, t.transform.rotation.w = q
    return t


class DemoSensors(Node):
    def __init__(self, name: str = "demo_sensors", **kwargs: object) -> None:
        super().__init__(name, **kwargs)
        fps = float(self.declare_parameter("fps", 30.0).value)
        k = pinhole_matrix()
        spots = [(-0.6, -0.4), (0.6, -0.4), (-0.6, 0.5), (0.6, 0.5)]
        self.pixels = render_markers(
            [(i, 0.4, FACING, np.array([x, y, 2.5])) for i, (x, y) in zip((3, 11, 27, 42), spots)], k)
        self.info = CameraInfo(width=640, height=480, distortion_model="plumb_bob", d=np.zeros(5), k=k.ravel(),
                               p=np.column_stack((k, np.zeros(3))).ravel())
        self.info.header.frame_id = "camera_optical_frame"
        self.ranges = self._room()
        self.image_pub = self.create_publisher(Image, "/camera/image_raw", 5)
        self.info_pub = self.create_publisher(CameraInfo, "/camera/camera_info", 5)
        self.scan_pub = self.create_publisher(LaserScan, "/scan", 5)
        self.tf = StaticTransformBroadcaster(self)
        self.tf.send_transform([_static("map", "base_link", (1.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0)),
                                _static("base_link", "camera_optical_frame", (0.1, 0.0, 0.3), OPTICAL),
                                _static("base_link", "laser", (0.0, 0.0, 0.2), (0.0, 0.0, 0.0, 1.0))])
        self.create_timer(1.0 / fps, self.tick)
        self.create_timer(0.1, self.scan)

    @staticmethod
    def _room(n: int = 360) -> np.ndarray:
        angles = -math.pi + 2 * math.pi / n * np.arange(n)
        ranges = np.full(n, 6.0)
        for ox, oy, r in ((2.0, 1.0, 0.25), (-1.5, -2.0, 0.3)):
            b = np.cos(angles) * ox + np.sin(angles) * oy
            disc = b * b - (ox * ox + oy * oy - r * r)
            hit = (disc >= 0) & (b > 0)
            ranges = np.where(hit, np.minimum(ranges, b - np.sqrt(np.where(hit, disc, 0))), ranges)
        return ranges.astype(np.float32)

    def tick(self) -> None:
        stamp = self.now().to_msg()
        image = Image(height=480, width=640, encoding="rgb8", step=1920, data=self.pixels.ravel())
        image.header.frame_id, image.header.stamp = "camera_optical_frame", stamp
        self.info.header.stamp = stamp
        self.info_pub.publish(self.info)
        self.image_pub.publish(image)

    def scan(self) -> None:
        n = len(self.ranges)
        scan = LaserScan(angle_min=-math.pi, angle_max=-math.pi + 2 * math.pi / n * (n - 1),
                         angle_increment=2 * math.pi / n, range_min=0.1, range_max=10.0, ranges=self.ranges)
        scan.header.frame_id, scan.header.stamp = "laser", self.now().to_msg()
        self.scan_pub.publish(scan)
