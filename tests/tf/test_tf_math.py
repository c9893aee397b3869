"""Transform maths: tf2's conventions for quaternions, Euler angles, slerp and A2B chains."""

from __future__ import annotations

import math

import numpy as np
import pytest
from numpy.testing import assert_array_almost_equal

from aiorobot.tf import (
    apply_transform,
    canonical_quaternion,
    concat,
    euler_from_quaternion,
    invert_transform,
    matrix_from_quaternion,
    pq_from_transform,
    quaternion_from_euler,
    quaternion_from_matrix,
    quaternion_inverse,
    quaternion_multiply,
    quaternion_slerp,
    rotate_vectors,
    transform_from_pq,
)

S45 = math.sin(math.pi / 4)


def random_quaternions(n: int, seed: int = 7) -> np.ndarray:
    rng = np.random.default_rng(seed)
    q = rng.normal(size=(n, 4))
    return q / np.linalg.norm(q, axis=1, keepdims=True)


def test_yaw_of_90_degrees_is_a_rotation_about_z():
    assert_array_almost_equal(quaternion_from_euler(0.0, 0.0, math.pi / 2), [0, 0, S45, S45])


def test_rpy_is_about_fixed_axes_roll_first():
    # fixed-axis XYZ: R = Rz(yaw) @ Ry(pitch) @ Rx(roll)
    roll, pitch, yaw = 0.3, -0.2, 1.1
    Rx = matrix_from_quaternion(quaternion_from_euler(roll, 0, 0))
    Ry = matrix_from_quaternion(quaternion_from_euler(0, pitch, 0))
    Rz = matrix_from_quaternion(quaternion_from_euler(0, 0, yaw))
    assert_array_almost_equal(matrix_from_quaternion(quaternion_from_euler(roll, pitch, yaw)), Rz @ Ry @ Rx)


def test_euler_round_trips_away_from_gimbal_lock():
    rng = np.random.default_rng(3)
    for roll, pitch, yaw in rng.uniform([-3, -1.5, -3], [3, 1.5, 3], size=(50, 3)):
        assert euler_from_quaternion(quaternion_from_euler(roll, pitch, yaw)) == pytest.approx(
            (roll, pitch, yaw), abs=1e-9
        )


@pytest.mark.parametrize("pitch", [math.pi / 2, -math.pi / 2])
def test_euler_at_gimbal_lock_puts_everything_in_roll(pitch):
    q = quaternion_from_euler(0.2, pitch, 0.4)
    roll, pitch_out, yaw = euler_from_quaternion(q)
    assert pitch_out == pytest.approx(pitch, abs=1e-5)
    assert yaw == 0.0
    # only roll -+ yaw is observable at pitch = +-90 deg: the rotation must still match
    R = matrix_from_quaternion(quaternion_from_euler(roll, pitch_out, yaw))
    assert_array_almost_equal(R, matrix_from_quaternion(q))


def test_matrix_and_quaternion_round_trip_up_to_sign():
    for q in random_quaternions(100):
        back = quaternion_from_matrix(matrix_from_quaternion(q))
        sign = 1.0 if np.dot(back, q) > 0 else -1.0
        assert_array_almost_equal(back, sign * q)


def test_canonical_sign_has_positive_w_when_the_trace_is_positive():
    for q in random_quaternions(200):
        c = canonical_quaternion(q)
        if np.trace(matrix_from_quaternion(q)) > 0:
            assert c[3] > 0
        assert_array_almost_equal(matrix_from_quaternion(c), matrix_from_quaternion(q))


def test_canonical_sign_of_a_half_turn_makes_the_largest_diagonal_component_positive():
    # 180 deg about x: trace -1, the x component is the one made positive
    assert_array_almost_equal(quaternion_from_matrix(np.diag([1.0, -1.0, -1.0])), [1, 0, 0, 0])
    assert_array_almost_equal(canonical_quaternion([0.0, -1.0, 0.0, 0.0]), [0, 1, 0, 0])


def test_canonical_quaternion_normalises():
    assert_array_almost_equal(canonical_quaternion([0, 0, 0, 2.0]), [0, 0, 0, 1])


def test_multiply_applies_the_right_factor_first():
    qx = quaternion_from_euler(math.pi / 2, 0, 0)
    qz = quaternion_from_euler(0, 0, math.pi / 2)
    R = matrix_from_quaternion(quaternion_multiply(qz, qx))
    assert_array_almost_equal(R, matrix_from_quaternion(qz) @ matrix_from_quaternion(qx))


def test_inverse_undoes_the_rotation():
    q = random_quaternions(1)[0]
    assert_array_almost_equal(canonical_quaternion(quaternion_multiply(q, quaternion_inverse(q))), [0, 0, 0, 1])


def test_slerp_halfway_is_half_the_angle():
    q1 = quaternion_from_euler(0, 0, math.pi / 2)
    mid = quaternion_slerp([0, 0, 0, 1], q1, 0.5)
    assert_array_almost_equal(mid, quaternion_from_euler(0, 0, math.pi / 4))


def test_slerp_takes_the_shortest_path_when_signs_disagree():
    q1 = -quaternion_from_euler(0, 0, math.pi / 2)  # same rotation, opposite sign
    mid = quaternion_slerp([0, 0, 0, 1], q1, 0.5)
    # a 45 deg rotation (not 135 deg), whatever the sign
    assert abs(np.dot(mid, quaternion_from_euler(0, 0, math.pi / 4))) == pytest.approx(1.0)


def test_slerp_ends_are_the_inputs():
    q0, q1 = random_quaternions(2, seed=11)
    assert_array_almost_equal(quaternion_slerp(q0, q1, 0.0), q0)
    end = quaternion_slerp(q0, q1, 1.0)
    assert abs(np.dot(end, q1)) == pytest.approx(1.0)


def test_slerp_of_equal_rotations_returns_the_first():
    q = random_quaternions(1, seed=5)[0]
    assert_array_almost_equal(quaternion_slerp(q, q, 0.3), q)


def test_concat_chains_a2b_then_b2c():
    rng = np.random.default_rng(1)
    qa, qb = random_quaternions(2, seed=2)
    A2B = transform_from_pq(rng.normal(size=3), qa)
    B2C = transform_from_pq(rng.normal(size=3), qb)
    p_A = rng.normal(size=(5, 3))
    assert_array_almost_equal(apply_transform(concat(A2B, B2C), p_A), apply_transform(B2C, apply_transform(A2B, p_A)))


def test_invert_transform_maps_back():
    A2B = transform_from_pq([1.0, -2.0, 0.5], random_quaternions(1, seed=9)[0])
    assert_array_almost_equal(concat(A2B, invert_transform(A2B)), np.eye(4))


def test_rotate_vectors_ignores_translation():
    A2B = transform_from_pq([5.0, 5.0, 5.0], quaternion_from_euler(0, 0, math.pi / 2))
    assert_array_almost_equal(rotate_vectors(A2B, [1.0, 0.0, 0.0]), [0.0, 1.0, 0.0])
    assert_array_almost_equal(apply_transform(A2B, [1.0, 0.0, 0.0]), [5.0, 6.0, 5.0])


def test_pq_round_trip():
    q = canonical_quaternion(random_quaternions(1, seed=4)[0])
    p, q_back = pq_from_transform(transform_from_pq([1, 2, 3], q))
    assert_array_almost_equal(p, [1, 2, 3])
    assert_array_almost_equal(q_back, q)


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda: matrix_from_quaternion([0, 0, 1]), r"^expected a quaternion of shape \(4,\) as \(x, y, z, w\), got shape \(3,\)$"),
        (lambda: matrix_from_quaternion([0, 0, 0, 0]), r"^expected a non-zero quaternion"),
        (lambda: quaternion_from_matrix(np.eye(4)), r"^expected a rotation matrix of shape \(3, 3\), got shape \(4, 4\)$"),
        (lambda: apply_transform(np.eye(3), [0, 0, 0]), r"^expected A2B as a homogeneous matrix of shape \(4, 4\)"),
        (lambda: apply_transform(np.eye(4), np.zeros((2, 2))), r"^expected points_A of shape \(3,\) or \(N, 3\), got shape \(2, 2\)$"),
        (lambda: transform_from_pq([0, 0], [0, 0, 0, 1]), r"^expected a translation of shape \(3,\), got shape \(2,\)$"),
    ],
)
def test_bad_shapes_say_what_was_expected_and_received(call, message):
    with pytest.raises(ValueError, match=message):
        call()


def test_canonical_fast_path_is_bit_identical_to_the_matrix_round_trip():
    # the inlined common branch of _canonical does the same operations as _m_to_q(_q_to_m(q))
    import random

    from aiorobot.tf._math import _canonical, _m_to_q, _q_to_m

    rng = random.Random(3)
    for _ in range(20000):
        q = [rng.gauss(0, 1) for _ in range(4)]
        n = math.sqrt(sum(v * v for v in q))
        q = tuple(v / n for v in q)
        assert _canonical(q) == _m_to_q(_q_to_m(q))
