"""Landmark fixes: the base pose in the map from one ArUco marker at a known place."""

from __future__ import annotations

import math

import numpy as np
import pytest

from aiorobot.nav import base_pose_from_marker, base_pose_from_markers, map_from_marker
from aiorobot.perception import detect_markers
from aiorobot.sim import CAMERA_XYZ, World
from aiorobot.sim._camera import CameraModel, MarkerRenderer, camera_pose_matrix


def _base_from_optical() -> np.ndarray:
    # base_link -> camera_link (CAMERA_XYZ, no rotation) -> camera_optical_frame
    return camera_pose_matrix(*CAMERA_XYZ, 0.0)


@pytest.mark.parametrize("pose", [(1.0, 0.0, 0.0), (0.5, 0.4, 0.3), (-0.2, -0.6, -0.25)])
def test_exact_marker_pose_gives_back_the_base_pose(pose: tuple[float, float, float]) -> None:
    x, y, yaw = pose
    marker = map_from_marker(3.0, 0.0, 0.25, math.pi)  # on the box's east wall, facing west
    map_from_optical = camera_pose_matrix(x + CAMERA_XYZ[0] * math.cos(yaw), y + CAMERA_XYZ[0] * math.sin(yaw),
                                          CAMERA_XYZ[2], yaw)
    optical_from_marker = np.linalg.inv(map_from_optical) @ marker
    got = base_pose_from_marker(marker, optical_from_marker, _base_from_optical())
    np.testing.assert_allclose(got, pose, atol=1e-9)
    np.testing.assert_allclose(base_pose_from_marker(marker, optical_from_marker, _base_from_optical(), yaw=yaw), pose,
                               atol=1e-9)


def test_a_rendered_and_detected_marker_fixes_the_pose_within_a_few_centimetres() -> None:
    world = World.load("box")
    camera = CameraModel()
    renderer = MarkerRenderer(world.landmarks, camera)
    x, y, yaw = 1.0, 0.2, 0.1
    image, _ = renderer.render(camera_pose_matrix(x + CAMERA_XYZ[0] * math.cos(yaw), y + CAMERA_XYZ[0] * math.sin(yaw),
                                               CAMERA_XYZ[2], yaw))
    found = detect_markers(image, camera.K, np.zeros(5), 0.2)
    assert found, "the marker on the east wall is in view"
    import cv2


    m = found[0]
    lm = world.landmark(m.marker_id)
    optical_from_marker = np.eye(4)
    optical_from_marker[:3, :3] = cv2.Rodrigues(m.rvec)[0]
    optical_from_marker[:3, 3] = np.ravel(m.tvec)
    gx, gy, gyaw = base_pose_from_marker(map_from_marker(lm.x, lm.y, lm.z, lm.yaw), optical_from_marker,
                                         _base_from_optical())
    # the marker's orientation from solvePnP is ambiguous at this size (tenths of a radian) ...
    # ... its position is not: with the heading known, the fix is within a few centimetres
    fx, fy, fyaw = base_pose_from_marker(map_from_marker(lm.x, lm.y, lm.z, lm.yaw), optical_from_marker,
                                         _base_from_optical(), yaw=yaw)
    assert math.hypot(fx - x, fy - y) < 0.04 and fyaw == yaw, (fx, fy)
    assert math.isfinite(gx + gy + gyaw)


def test_bad_shapes_are_named() -> None:
    with pytest.raises(ValueError, match=r"optical_from_marker must have shape \(4, 4\), got shape \(3, 3\)"):
        base_pose_from_marker(np.eye(4), np.eye(3), np.eye(4))


def _seen_from(pose: tuple[float, float, float], marker: np.ndarray) -> np.ndarray:
    x, y, yaw = pose
    map_from_optical = camera_pose_matrix(x + CAMERA_XYZ[0] * math.cos(yaw), y + CAMERA_XYZ[0] * math.sin(yaw),
                                          CAMERA_XYZ[2], yaw)
    return np.linalg.inv(map_from_optical) @ marker


@pytest.mark.parametrize("pose", [(1.0, 0.0, 0.0), (0.5, 0.4, 0.3), (-0.2, -0.6, -0.25)])
def test_two_markers_give_the_heading_from_their_positions_alone(pose: tuple[float, float, float]) -> None:
    markers = [map_from_marker(3.0, -0.8, 0.25, math.pi), map_from_marker(3.0, 0.9, 0.25, math.pi)]
    seen = [_seen_from(pose, m) for m in markers]
    np.testing.assert_allclose(base_pose_from_markers(markers, seen, _base_from_optical()), pose, atol=1e-9)
    # the markers' orientations are not used: spin each seen marker about its own centre
    spun = [s @ np.array([[0.0, -1.0, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0, 0, 0, 1.0]]) for s in seen]
    np.testing.assert_allclose(base_pose_from_markers(markers, spun, _base_from_optical()), pose, atol=1e-9)


def test_noisy_marker_positions_give_a_least_squares_heading() -> None:
    rng = np.random.default_rng(3)
    pose = (0.7, -0.2, 0.2)
    markers = [map_from_marker(3.0, y, 0.25, math.pi) for y in (-1.5, -0.5, 0.5, 1.5)]
    seen = []
    for m in markers:
        s = _seen_from(pose, m)
        s[:3, 3] += rng.normal(0.0, 0.01, 3)  # 1 cm of position noise per marker
        seen.append(s)
    x, y, yaw = base_pose_from_markers(markers, seen, _base_from_optical())
    assert math.hypot(x - pose[0], y - pose[1]) < 0.03 and abs(yaw - pose[2]) < 0.02


def test_one_marker_is_not_enough_for_the_heading() -> None:
    with pytest.raises(ValueError, match="expected two or more"):
        base_pose_from_markers([np.eye(4)], [np.eye(4)], np.eye(4))
