"""Colour blobs, LaserScan -> points, breakpoint segmentation, obstacles, voxel downsampling: known geometry."""

from __future__ import annotations

import math

import numpy as np
import pytest

from aiorobot.msgs.sensor_msgs import LaserScan
from aiorobot.perception import (
    BadInput,
    cloud_to_xyz,
    detect_blobs,
    extract_obstacles,
    scan_to_points,
    segment_scan,
    voxel_downsample,
    xyz_to_cloud,
)


def test_blobs_find_red_discs_at_their_centres():
    import cv2

    image = np.full((480, 640, 3), 40, np.uint8)
    cv2.circle(image, (100, 120), 30, (255, 0, 0), -1)  # red in RGB
    cv2.circle(image, (500, 400), 15, (250, 10, 10), -1)
    cv2.circle(image, (300, 300), 40, (0, 0, 255), -1)  # blue: not matched
    blobs = detect_blobs(image, (0, 150, 100), (10, 255, 255))
    assert len(blobs) == 2
    assert np.allclose(blobs[0].centroid, (100, 120), atol=0.5)
    assert np.allclose(blobs[1].centroid, (500, 400), atol=0.5)
    assert blobs[0].area == pytest.approx(math.pi * 30**2, rel=0.05)
    assert blobs[0].bbox == (70, 90, 61, 61)


def make_scan(ranges, angle_min=-math.pi, increment=None, intensities=()):
    ranges = np.asarray(ranges, np.float32)
    increment = increment if increment is not None else 2 * math.pi / len(ranges)
    return LaserScan(angle_min=angle_min, angle_max=angle_min + increment * (len(ranges) - 1),
                     angle_increment=increment, range_min=0.1, range_max=10.0, ranges=ranges,
                     intensities=np.asarray(intensities, np.float32))


def circle_scan(n=360, walls=8.0, obstacles=((2.0, 0.0, 0.2), (0.0, 3.0, 0.3))):
    """Ranges of a lidar at the origin seeing circular obstacles (x, y, r) in front of a circular wall."""
    angles = -math.pi + 2 * math.pi / n * np.arange(n)
    ranges = np.full(n, walls)
    for ox, oy, r in obstacles:
        d = np.array([np.cos(angles), np.sin(angles)])
        b = d[0] * ox + d[1] * oy
        c = ox * ox + oy * oy - r * r
        disc = b * b - c
        hit = (disc >= 0) & (b > 0)
        t = b - np.sqrt(np.where(hit, disc, 0))
        ranges = np.where(hit & (t < ranges), t, ranges)
    return ranges


def test_scan_to_points_skips_nan_inf_and_out_of_range():
    scan = make_scan([1.0, np.nan, np.inf, 0.05, 2.0, 11.0, -np.inf, 3.0], angle_min=0.0, increment=math.pi / 2)
    points = scan_to_points(scan)
    assert np.allclose(points, [[1, 0], [2.0, 0], [0, -3.0]], atol=1e-6)  # beams 0, 4 (2 pi), 7


@pytest.mark.parametrize("bad, message", [
    (dict(intensities=[1.0, 2.0]), r"^scan has 4 ranges but 2 intensities$"),
    (dict(increment=0.0), r"non-zero increment"),
])
def test_scan_with_mismatched_lengths_is_bad_input(bad, message):
    with pytest.raises(BadInput, match=message):
        scan_to_points(make_scan([1.0, 1.0, 1.0, 1.0], angle_min=0.0, **({"increment": 0.1} | bad)))


def test_scan_whose_angles_disagree_with_its_ranges_is_bad_input():
    scan = make_scan(np.ones(360))
    scan.angle_max = 0.0
    with pytest.raises(BadInput, match=r"^scan has 360 ranges but angle_min..angle_max/angle_increment gives 181$"):
        scan_to_points(scan)


def test_segmentation_and_obstacles_recover_circles():
    points = scan_to_points(make_scan(circle_scan()))
    labels = segment_scan(points, break_distance=0.3, min_points=3)
    obstacles = extract_obstacles(points, labels)
    near = obstacles[np.hypot(obstacles[:, 0], obstacles[:, 1]) < 5]
    near = near[np.argsort(near[:, 0])[::-1]]
    assert len(near) == 2
    # the visible arc's centroid sits in front of the centre, by less than the radius
    assert np.hypot(near[0, 0] - 2.0, near[0, 1]) < 0.2
    assert np.hypot(near[1, 0], near[1, 1] - 3.0) < 0.3
    assert np.all(near[:, 3] >= 3)


def test_segmentation_labels_small_segments_minus_one():
    points = np.array([[0, 0], [0.1, 0], [0.2, 0], [5, 5], [9, 9], [9.1, 9], [9.2, 9], [9.3, 9]], float)
    assert segment_scan(points, 0.5, 3).tolist() == [0, 0, 0, -1, 1, 1, 1, 1]
    assert segment_scan(np.zeros((0, 2)), 0.5, 3).tolist() == []
    with pytest.raises(ValueError, match=r"^points must be \(N, 2\), got shape \(3,\)$"):
        segment_scan(np.zeros(3))


def test_voxel_downsample_keeps_one_centroid_per_voxel():
    rng = np.random.default_rng(3)
    centres = np.array([[0.05, 0.05, 0.05], [1.05, 0.05, 0.05], [0.05, 2.05, 0.05]])
    points = np.concatenate([c + rng.uniform(-0.04, 0.04, (100, 3)) for c in centres])
    rng.shuffle(points)
    down = voxel_downsample(points, 0.1)
    assert down.shape == (3, 3)
    assert np.allclose(np.sort(down, axis=0), np.sort(centres, axis=0), atol=0.01)
    with pytest.raises(ValueError, match=r"^voxel_size must be > 0, got 0.0$"):
        voxel_downsample(points, 0.0)


def test_pointcloud2_round_trip_and_downsample():
    from aiorobot.msgs import deserialize, serialize

    pts = np.array([[1, 2, 3], [1.01, 2.01, 3.01], [np.nan, 0, 0], [4, 5, 6]], float)
    msg = deserialize(serialize(xyz_to_cloud(pts, "laser")), type(xyz_to_cloud(pts)))
    xyz = cloud_to_xyz(msg)
    assert np.allclose(xyz, pts[[0, 1, 3]], atol=1e-6)
    assert len(voxel_downsample(xyz, 0.5)) == 2
    msg.point_step = 16
    with pytest.raises(BadInput, match=r"^PointCloud2 data has 48 bytes, expected width\*height\*point_step = 4\*1\*16$"):
        cloud_to_xyz(msg)
