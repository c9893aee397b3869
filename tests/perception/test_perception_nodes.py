"""The ArUco node, the scan obstacle node and the detection map, wired through topics and tf."""

from __future__ import annotations

import math

import numpy as np

from aiorobot import Node, Runtime
from aiorobot.msgs.geometry_msgs import Pose, PoseArray, TransformStamped
from aiorobot.msgs.sensor_msgs import CameraInfo, Image, LaserScan, PointCloud2
from aiorobot.perception import (
    ArucoNode,
    DetectionMapNode,
    MarkerDetection,
    MarkerDetectionArray,
    ScanObstacleNode,
    cloud_to_xyz,
    pinhole_matrix,
    render_markers,
)
from aiorobot.tf import StaticTransformBroadcaster

from _perception_helpers import wait_until

FACING = np.diag([1.0, -1.0, -1.0])  # rotation by pi about x: the marker faces the camera
K = pinhole_matrix()


def camera_info() -> CameraInfo:
    return CameraInfo(width=640, height=480, distortion_model="plumb_bob", d=np.zeros(5), k=K.ravel(),
                      p=np.column_stack((K, np.zeros(3))).ravel())


def rgb_image(pixels: np.ndarray, sec: int = 1) -> Image:
    msg = Image(height=pixels.shape[0], width=pixels.shape[1], encoding="rgb8", step=pixels.shape[1] * 3,
                data=pixels.ravel())
    msg.header.frame_id = "camera_optical_frame"
    msg.header.stamp.sec = sec
    return msg


class Rig(Node):
    def __init__(self) -> None:
        super().__init__("rig")
        self.image_pub = self.create_publisher(Image, "/camera/image_raw", 10)
        self.info_pub = self.create_publisher(CameraInfo, "/camera/camera_info", 10)
        self.scan_pub = self.create_publisher(LaserScan, "/scan", 10)
        self.markers_pub = self.create_publisher(MarkerDetectionArray, "/detections/markers", 10)
        self.obstacles_pub = self.create_publisher(PoseArray, "/obstacles", 10)
        self.got: dict[str, list] = {"markers": [], "obstacles": [], "points": [], "map_markers": [],
                                     "map_obstacles": []}
        for key, topic, t in (("markers", "/detections/markers", MarkerDetectionArray),
                              ("obstacles", "/obstacles", PoseArray), ("points", "/scan/points", PointCloud2),
                              ("map_markers", "/detection_map/markers", PoseArray),
                              ("map_obstacles", "/detection_map/obstacles", PoseArray)):
            self.create_subscription(t, topic, self.got[key].append, 100)


async def test_aruco_node_publishes_ids_and_poses_after_camera_info():
    async with Runtime() as rt:
        aruco = rt.add_node(ArucoNode(parameter_overrides={"marker_length": 0.5, "workers": 1}))
        rig = rt.add_node(Rig())
        frame = render_markers([(4, 0.5, FACING, np.array([-0.5, 0.0, 2.0])), (9, 0.5, FACING, np.array([0.6, 0.1, 2.5]))], K)
        rig.image_pub.publish(rgb_image(frame))  # no camera_info yet: dropped
        await wait_until(lambda: aruco.pipeline.statistics().dropped_bad_input == 1)
        rig.info_pub.publish(camera_info())
        await wait_until(lambda: aruco._camera is not None)
        rig.image_pub.publish(rgb_image(frame, sec=2))
        await wait_until(lambda: len(rig.got["markers"]) == 1)
        msg = rig.got["markers"][0]
        assert msg.header.frame_id == "camera_optical_frame" and msg.header.stamp.sec == 2
        assert [d.marker_id for d in msg.detections] == [4, 9]
        positions = np.array([[d.pose.position.x, d.pose.position.y, d.pose.position.z] for d in msg.detections])
        assert np.allclose(positions, [[-0.5, 0.0, 2.0], [0.6, 0.1, 2.5]], atol=0.03)
        q = msg.detections[0].pose.orientation
        assert abs(abs(q.x) - 1.0) < 0.02  # pi about x
        assert msg.detections[0].corners.shape == (8,)


def circle_scan(n: int = 360) -> LaserScan:
    angles = -math.pi + 2 * math.pi / n * np.arange(n)
    ranges = np.full(n, 8.0)
    ox, oy, r = 2.0, 0.0, 0.2
    b = np.cos(angles) * ox + np.sin(angles) * oy
    disc = b * b - (ox * ox + oy * oy - r * r)
    hit = (disc >= 0) & (b > 0)
    ranges = np.where(hit, b - np.sqrt(np.where(hit, disc, 0)), ranges)
    scan = LaserScan(angle_min=-math.pi, angle_max=-math.pi + 2 * math.pi / n * (n - 1),
                     angle_increment=2 * math.pi / n, range_min=0.1, range_max=10.0,
                     ranges=ranges.astype(np.float32))
    scan.header.frame_id = "laser"
    scan.header.stamp.sec = 3
    return scan


async def test_scan_node_publishes_obstacles_and_points_and_drops_bad_scans(caplog):
    async with Runtime() as rt:
        node = rt.add_node(ScanObstacleNode(parameter_overrides={"break_distance": 0.3}))
        rig = rt.add_node(Rig())
        bad = circle_scan()
        bad.intensities = np.ones(10, np.float32)
        rig.scan_pub.publish(bad)
        await wait_until(lambda: node.dropped == 1)
        scan = circle_scan()
        scan.ranges[:5] = np.nan
        scan.ranges[5:8] = np.inf
        rig.scan_pub.publish(scan)
        await wait_until(lambda: rig.got["obstacles"] and rig.got["points"])
        (obstacle,) = rig.got["obstacles"][0].poses  # the wall's segment is larger than max_radius
        assert math.hypot(obstacle.position.x - 2.0, obstacle.position.y) < 0.2
        assert rig.got["obstacles"][0].header.frame_id == "laser"
        assert len(cloud_to_xyz(rig.got["points"][0])) == 360 - 8
    assert any("scan has 360 ranges but 10 intensities" in r.getMessage() for r in caplog.records)


def static(parent: str, child: str, x: float, y: float, z: float, q=(0.0, 0.0, 0.0, 1.0)) -> TransformStamped:
    t = TransformStamped()
    t.header.frame_id, t.child_frame_id = parent, child
    t.transform.translation.x, t.transform.translation.y, t.transform.translation.z = x, y, z
    (t.transform.rotation.x, t.transform.rotation.y, t.transform.rotation.z, t.transform.rotation.w) = q
    return t


async def test_detection_map_puts_camera_and_lidar_detections_in_the_map_frame():
    async with Runtime() as rt:
        mapper = rt.add_node(DetectionMapNode())
        rig = rt.add_node(Rig())
        broadcaster = StaticTransformBroadcaster(rig)
        # camera optical frame: z forward along map x, x along map -y, y along map -z; camera at (1, 0, 0.5)
        half = math.sqrt(0.5)
        optical = (-0.5, 0.5, -0.5, 0.5)
        broadcaster.send_transform([static("map", "base_link", 1.0, 0.0, 0.0),
                                   static("base_link", "camera_optical_frame", 0.0, 0.0, 0.5, optical),
                                   static("base_link", "laser", 0.2, 0.0, 0.1, (0.0, 0.0, half, half))])
        markers = MarkerDetectionArray()
        markers.header.frame_id, markers.header.stamp.sec = "camera_optical_frame", 5
        detection = MarkerDetection(marker_id=7, marker_length=0.5)
        detection.pose.position.x, detection.pose.position.y, detection.pose.position.z = 0.5, -0.2, 3.0
        markers.detections = [detection]
        obstacles = PoseArray()
        obstacles.header.frame_id, obstacles.header.stamp.sec = "laser", 5
        pose = Pose()
        pose.position.x = 2.0  # 2 m ahead of a laser turned 90 degrees left: map y = +2
        obstacles.poses = [pose]
        rig.markers_pub.publish(markers)
        rig.obstacles_pub.publish(obstacles)
        await wait_until(lambda: mapper.state.updates == 2)
        assert mapper.state.markers[7].sightings == 1
        assert np.allclose(mapper.state.markers[7].position, [1.0 + 3.0, -0.5, 0.5 + 0.2], atol=1e-9)
        assert np.allclose(mapper.state.obstacles, [[1.2, 2.0, 0.1]], atol=1e-9)
        detection.pose.position.z = 3.2
        rig.markers_pub.publish(markers)
        await wait_until(lambda: mapper.state.updates == 3)
        assert mapper.state.markers[7].sightings == 2
        assert mapper.state.markers[7].position[0] == 1.0 + 3.1
        await wait_until(lambda: len(rig.got["map_markers"]) >= 3)
        assert rig.got["map_markers"][-1].header.frame_id == "map"
        subs = [s for s in mapper._subscriptions if s.topic_name in ("/detections/markers", "/obstacles")]
        assert len(subs) == 2 and all(s.callback_group is mapper.group for s in subs)


async def test_detection_map_drops_what_it_cannot_transform(caplog):
    async with Runtime() as rt:
        mapper = rt.add_node(DetectionMapNode(parameter_overrides={"tf_timeout_sec": 0.05}))
        rig = rt.add_node(Rig())
        obstacles = PoseArray()
        obstacles.header.frame_id = "nowhere"
        obstacles.poses = [Pose()]
        rig.obstacles_pub.publish(obstacles)
        await wait_until(lambda: mapper.dropped == 1)
        assert mapper.state.updates == 0
    assert any("dropped a message from 'nowhere'" in r.getMessage() for r in caplog.records)
