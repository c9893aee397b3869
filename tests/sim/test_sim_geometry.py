"""Ray casting, camera projection and the sensor/robot models against geometry, without a runtime."""

from __future__ import annotations

import math

import cv2
import numpy as np
import pytest

from aiorobot.control import Mecanum
from aiorobot.sim import (
    GRAVITY,
    CameraModel,
    ImuModel,
    LidarModel,
    MarkerRenderer,
    RobotBody,
    World,
    camera_pose_matrix,
    project_landmark,
    raycast,
)


def _brute_force(grid: np.ndarray, res: float, x: float, y: float, angle: float, max_range: float) -> float:
    step = res / 200.0
    for k in range(1, int(max_range / step)):
        d = k * step
        col = math.floor((x + d * math.cos(angle)) / res)
        row = math.floor((y + d * math.sin(angle)) / res)
        if not (0 <= row < grid.shape[0] and 0 <= col < grid.shape[1]):
            return math.inf
        if grid[row, col]:
            return d
    return math.inf


def test_forward_beam_in_box_reads_the_wall_exactly() -> None:
    world = World.load("box")
    angles = np.array([0.0, 0.5 * math.pi, math.pi, -0.5 * math.pi, 0.25 * math.pi])
    ranges = raycast(world.occupied, world.resolution, world.origin[:2], (0.0, 0.0), angles)
    np.testing.assert_allclose(ranges, [3.0, 3.0, 3.0, 3.0, 3.0 * math.sqrt(2)], atol=1e-9)


def test_raycast_matches_fine_sampling_on_a_random_grid() -> None:
    rng = np.random.default_rng(7)
    grid = (rng.random((40, 50)) < 0.08).astype(np.uint8)
    grid[18:22, 23:27] = 0
    angles = rng.uniform(-math.pi, math.pi, 40)
    ranges = raycast(grid, 0.1, (0.0, 0.0), (2.5, 2.0), angles, 6.0)
    for angle, r in zip(angles, ranges):
        expected = _brute_force(grid, 0.1, 2.5, 2.0, angle, 6.0)
        if math.isinf(expected):
            assert math.isinf(r) or r > 6.0 - 0.01
        else:
            assert r == pytest.approx(expected, abs=0.1 / 150)


def test_raycast_edge_cases() -> None:
    grid = np.zeros((10, 10), dtype=np.uint8)
    grid[5, 5] = 1
    assert raycast(grid, 1.0, (0.0, 0.0), (5.5, 5.5), np.array([0.0]))[0] == 0.0
    assert math.isinf(raycast(grid, 1.0, (0.0, 0.0), (1.5, 1.5), np.array([0.0]))[0])  # leaves the grid
    assert math.isinf(raycast(grid, 1.0, (0.0, 0.0), (20.0, 1.5), np.array([0.0]))[0])  # starts outside
    assert math.isinf(raycast(grid, 1.0, (0.0, 0.0), (1.5, 5.5), np.array([0.0]), max_range=2.0)[0])
    with pytest.raises(ValueError, match=r"occupied must have shape \(height, width\), got shape \(10,\)"):
        raycast(np.zeros(10), 1.0, (0.0, 0.0), (0.0, 0.0), np.array([0.0]))


def test_lidar_forward_beam_reads_three_metres_within_the_noise_model() -> None:
    world = World.load("box")
    lidar = LidarModel(noise_std=0.01)
    rng = np.random.default_rng(3)
    forward = lidar.beams // 2  # angle 0 in the laser frame
    assert lidar.angles[forward] == pytest.approx(0.0)
    readings = np.array([lidar.measure(world, 0.0, 0.0, 0.0, rng)[forward] for _ in range(200)])
    assert abs(readings.mean() - 3.0) < 4 * 0.01 / math.sqrt(200)
    assert readings.std() == pytest.approx(0.01, rel=0.2)
    assert np.all(np.abs(readings - 3.0) < 5 * 0.01)
    far = LidarModel(range_max=2.0, noise_std=0.0).measure(world, 0.0, 0.0, 0.0, rng)
    assert np.all(np.isposinf(far))  # REP 117: no return within range_max


@pytest.fixture(scope="module")
def detector() -> cv2.aruco.ArucoDetector:
    params = cv2.aruco.DetectorParameters()
    params.cornerRefinementMethod = cv2.aruco.CORNER_REFINE_SUBPIX
    return cv2.aruco.ArucoDetector(cv2.aruco.getPredefinedDictionary(cv2.aruco.DICT_4X4_50), params)


@pytest.mark.parametrize(("x", "y", "yaw"), [(0.1, 0.0, 0.0), (1.1, 0.3, 0.2), (2.1, -0.2, 0.1), (-0.9, 0.4, 0.1)])
def test_camera_frame_facing_id_0_decodes_at_the_projected_corners(detector, x: float, y: float, yaw: float) -> None:
    world = World.load("box")
    camera = CameraModel()
    renderer = MarkerRenderer(world.landmarks, camera)
    pose = camera_pose_matrix(x, y, 0.25, yaw)
    image, drawn = renderer.render(pose)
    assert image.shape == (480, 640, 3) and image.dtype == np.uint8
    assert drawn == [0]
    corners, ids, _ = detector.detectMarkers(image)
    assert ids is not None and ids.ravel().tolist() == [0]
    expected = project_landmark(world.landmark(0), pose, camera)
    assert expected is not None
    assert np.abs(corners[0][0] - expected).max() < 1.0


def test_pinhole_projection_of_a_marker_straight_ahead() -> None:
    world = World.load("box")
    camera = CameraModel()
    pose = camera_pose_matrix(1.0, 0.0, 0.25, 0.0)  # 2 m from the marker, looking at its centre
    corners = project_landmark(world.landmark(0), pose, camera)
    half = 500 * 0.1 / 2.0  # f * (size / 2) / distance
    np.testing.assert_allclose(
        corners, [[320 - half, 240 - half], [320 + half, 240 - half], [320 + half, 240 + half], [320 - half, 240 + half]]
    )
    assert project_landmark(world.landmark(2), pose, camera) is None  # behind the camera
    assert project_landmark(world.landmark(0), camera_pose_matrix(1.0, 0.0, 0.25, math.pi), camera) is None


def test_markers_seen_from_behind_or_vetoed_are_not_drawn() -> None:
    world = World.load("box")
    renderer = MarkerRenderer(world.landmarks, CameraModel())
    _, drawn = renderer.render(camera_pose_matrix(0.0, 0.0, 0.25, 0.0), visible=lambda lm, pos: False)
    assert drawn == []
    blank, drawn = renderer.render(camera_pose_matrix(0.0, 0.0, 0.25, math.pi / 4))
    assert drawn == [] and np.array_equal(blank, renderer.background())


def test_imu_at_rest_reads_gravity_and_its_bias() -> None:
    imu = ImuModel(gyro_noise_std=0.001, gyro_bias_std=0.01, gyro_bias_walk_std=0.0, accel_noise_std=0.01,
                   rng=np.random.default_rng(5))
    samples = [imu.measure(0.0, np.zeros(2), 0.01) for _ in range(400)]
    gyro = np.mean([g for g, _ in samples], axis=0)
    accel = np.mean([a for _, a in samples], axis=0)
    np.testing.assert_allclose(gyro, imu.gyro_bias, atol=4 * 0.001 / 20)
    np.testing.assert_allclose(accel, [0.0, 0.0, GRAVITY], atol=4 * 0.01 / 20)
    with pytest.raises(ValueError, match=r"gyro_noise_std: expected a number >= 0, found -1"):
        ImuModel(gyro_noise_std=-1, rng=np.random.default_rng(0))


def test_robot_stops_at_a_wall_and_counts_the_collision() -> None:
    world = World.load("box")
    body = RobotBody(Mecanum(0.05, 0.15, 0.15), radius=0.2)
    body.set_command((1.0, 0.0, 0.0))
    for _ in range(1000):
        body.step(0.01, world)
    assert body.pose[0] == pytest.approx(2.8, abs=0.02)
    assert body.collisions == 1 and body.in_contact
    body.set_command((-0.5, 0.0, 0.0))
    for _ in range(100):
        body.step(0.01, world)
    assert not body.in_contact and body.pose[0] < 2.5
    with pytest.raises(ValueError, match=r"twist: expected finite values"):
        body.set_command((math.nan, 0.0, 0.0))


def test_odometry_drifts_by_its_scale_error_while_truth_slips() -> None:
    world = World.load("box")
    body = RobotBody(Mecanum(0.05, 0.15, 0.15), wheel_slip=0.1, odom_scale_error=0.05, max_acceleration=(1e3, 1e3, 1e3))
    body.set_command((0.2, 0.0, 0.0))
    for _ in range(500):
        body.step(0.01, world)
    assert body.pose[0] == pytest.approx(0.2 * 5 * 0.9)
    assert body.odom_pose[0] == pytest.approx(0.2 * 5 * 1.05)
    # the wheels turned what the command asked: r * angle = distance
    np.testing.assert_allclose(body.wheel_positions * 0.05, [1.0, 1.0, 1.0, 1.0])


def test_the_simulators_fast_arc_matches_the_control_package() -> None:
    from aiorobot.control import integrate_twist as reference
    from aiorobot.sim._robot import integrate_twist

    rng = np.random.default_rng(11)
    for _ in range(50):
        pose, twist, dt = rng.normal(size=3), rng.normal(size=3), float(rng.uniform(0, 0.1))
        np.testing.assert_allclose(integrate_twist(pose, twist, dt), reference(pose, twist, dt), atol=1e-12)
    np.testing.assert_allclose(integrate_twist(np.zeros(3), np.array([1.0, 0.0, 1e-9]), 0.01),
                               reference(np.zeros(3), np.array([1.0, 0.0, 1e-9]), 0.01), atol=1e-12)


def test_leaping_through_open_space_gives_the_same_distances() -> None:
    from aiorobot.sim import clearance_map

    rng = np.random.default_rng(21)
    grid = (rng.random((120, 150)) < 0.01).astype(np.uint8)
    grid[:2], grid[-2:], grid[:, :2], grid[:, -2:] = 1, 1, 1, 1
    clearance = clearance_map(grid)
    angles = rng.uniform(-math.pi, math.pi, 200)
    for _ in range(20):
        x, y = rng.uniform(0.2, 7.3), rng.uniform(0.2, 5.8)
        plain = raycast(grid, 0.05, (0.0, 0.0), (x, y), angles, 12.0)
        leaping = raycast(grid, 0.05, (0.0, 0.0), (x, y), angles, 12.0, clearance=clearance)
        np.testing.assert_allclose(leaping, plain, atol=1e-9)


def test_free_disc_fast_path_agrees_with_the_cell_check() -> None:
    world = World.load("warehouse")
    rng = np.random.default_rng(2)
    for _ in range(300):
        x, y, r = rng.uniform(-10.4, 10.4), rng.uniform(-7.4, 7.4), rng.uniform(0.05, 1.0)
        exact = world.is_free_disc(x, y, r)
        ox, oy, _ = world.origin
        res = world.resolution
        c0, c1 = math.floor((x - r - ox) / res), math.floor((x + r - ox) / res)
        r0, r1 = math.floor((y - r - oy) / res), math.floor((y + r - oy) / res)
        h, w = world.occupied.shape
        if c0 < 0 or r0 < 0 or c1 >= w or r1 >= h:
            assert not exact
            continue
        rows, cols = np.nonzero(world.occupied[r0 : r1 + 1, c0 : c1 + 1])
        cx0, cy0 = ox + (cols + c0) * res, oy + (rows + r0) * res
        dx, dy = np.clip(x, cx0, cx0 + res) - x, np.clip(y, cy0, cy0 + res) - y
        assert exact == bool(np.all(dx * dx + dy * dy > r * r))
