"""ArUco detection + pose against markers rendered at known poses with OpenCV."""

from __future__ import annotations

import math

import numpy as np
import pytest

from aiorobot.perception import detect_markers, pinhole_matrix, render_markers


def rot_x(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def rot_y(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


FACING = rot_x(math.pi)  # marker z towards the camera, marker +y up in the image
K = pinhole_matrix()


@pytest.mark.parametrize(
    "length, bound", [(0.5, 0.02), (0.3, 0.025), (0.2, 0.03)], ids=["0.5m", "0.3m", "0.2m"]
)
def test_position_error_per_marker_size_at_two_metres(length, bound, record_property):
    rng = np.random.default_rng(7)
    errors = []
    for trial in range(6):
        marker_id = int(rng.integers(0, 50))
        t = np.array([rng.uniform(-0.4, 0.4), rng.uniform(-0.3, 0.3), 2.0])
        r = rot_y(rng.uniform(-0.4, 0.4)) @ FACING
        frame = render_markers([(marker_id, length, r, t)], K)
        found = detect_markers(frame, K, None, length)
        assert [m.marker_id for m in found] == [marker_id]
        errors.append(float(np.linalg.norm(found[0].tvec - t)))
    record_property(f"max_error_m_{length}", max(errors))
    print(f"marker {length} m at 2 m: position error max {max(errors) * 100:.2f} cm, "
          f"mean {np.mean(errors) * 100:.2f} cm")
    assert max(errors) < bound


def test_four_markers_in_one_frame_ids_exact_and_corners_match_projection():
    markers = [(i, 0.4, FACING, np.array([x, y, 2.5]))
               for i, (x, y) in zip([3, 11, 27, 42], [(-0.6, -0.4), (0.6, -0.4), (-0.6, 0.5), (0.6, 0.5)])]
    frame = render_markers(markers, K)
    found = detect_markers(frame, K, np.zeros(5), 0.4)
    assert [m.marker_id for m in found] == [3, 11, 27, 42]
    for m, (_, _, _, t) in zip(found, markers):
        assert np.linalg.norm(m.tvec - t) < 0.03
        centre = K @ t
        assert np.allclose(m.corners.mean(axis=0), centre[:2] / centre[2], atol=1.5)
        # corner order: top-left, top-right, bottom-right, bottom-left
        assert m.corners[0, 0] < m.corners[1, 0] and m.corners[0, 1] < m.corners[3, 1]


def test_orientation_is_recovered():
    r = rot_y(0.5) @ FACING
    frame = render_markers([(5, 0.5, r, np.array([0.0, 0.0, 2.0]))], K)
    import cv2

    (m,) = detect_markers(frame, K, None, 0.5)
    recovered, _ = cv2.Rodrigues(m.rvec)
    angle = math.acos(max(-1.0, min(1.0, (np.trace(recovered.T @ r) - 1) / 2)))
    assert angle < math.radians(3)


def test_no_markers_gives_an_empty_list():
    assert detect_markers(np.full((480, 640, 3), 128, np.uint8), K, None, 0.5) == []


def test_draw_markers_outlines_each_marker_in_green_and_leaves_the_input_alone():
    from aiorobot.perception import draw_markers

    frame = render_markers([(5, 0.5, FACING, np.array([0.0, 0.0, 2.0]))], K)
    found = detect_markers(frame, K, None, 0.5)
    drawn = draw_markers(frame, found, K, 0.5)
    assert not np.array_equal(drawn, frame) and np.all(frame[:, :, 0] == frame[:, :, 1])
    x, y = found[0].corners[0].round().astype(int)
    patch = drawn[y - 2:y + 3, x - 2:x + 3].reshape(-1, 3)
    assert any((p == (0, 255, 0)).all() for p in patch)
