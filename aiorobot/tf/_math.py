"""Rigid transform maths, with tf2's conventions and numerics.

Quaternions are ``(x, y, z, w)`` as in ROS messages. A transform ``A2B`` maps
coordinates expressed in frame A to frame B: ``p_B = apply_transform(A2B, p_A)``;
a ``geometry_msgs/TransformStamped`` with ``header.frame_id = parent`` and
``child_frame_id = child`` holds ``child2parent``. ``concat(A2B, B2C)`` is ``A2C``.

The public functions take and return numpy arrays. The underscore helpers at the
bottom work on plain tuples of floats: the buffer calls them on its hot path,
where a 4-element numpy operation costs ten times more than the arithmetic.
They reproduce tf2's LinearMath formulas (quaternion product, ``quatRotate``,
``slerp`` along the shortest path, ``Matrix3x3::getRotation``) so that results
compare component-wise with tf2's.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "apply_transform",
    "canonical_quaternion",
    "check_quaternion",
    "concat",
    "euler_from_quaternion",
    "invert_transform",
    "matrix_from_quaternion",
    "pq_from_transform",
    "quaternion_from_euler",
    "quaternion_from_matrix",
    "quaternion_inverse",
    "quaternion_multiply",
    "quaternion_slerp",
    "rotate_vectors",
    "transform_from_pq",
]

Quat = tuple[float, float, float, float]
Vec = tuple[float, float, float]
Mat = tuple[float, float, float, float, float, float, float, float, float]

IDENTITY_QUAT: Quat = (0.0, 0.0, 0.0, 1.0)


# --------------------------------------------------------------------------- checks


def check_quaternion(q: ArrayLike) -> NDArray[np.float64]:
    """Return ``q`` as a float64 array of shape (4,), ``(x, y, z, w)``.

    Raises
    ------
    ValueError
        If ``q`` does not have shape (4,) or has zero norm.
    """
    arr = np.asarray(q, dtype=np.float64)
    if arr.shape != (4,):
        raise ValueError(
            f"expected a quaternion of shape (4,) as (x, y, z, w), got shape {arr.shape}"
        )
    if not np.any(arr):
        raise ValueError("expected a non-zero quaternion, got (0, 0, 0, 0); identity is (0, 0, 0, 1)")
    return arr


def _check_transform(A2B: ArrayLike, name: str = "A2B") -> NDArray[np.float64]:
    arr = np.asarray(A2B, dtype=np.float64)
    if arr.shape != (4, 4):
        raise ValueError(f"expected {name} as a homogeneous matrix of shape (4, 4), got shape {arr.shape}")
    return arr


def _check_vectors(v: ArrayLike, name: str) -> NDArray[np.float64]:
    arr = np.asarray(v, dtype=np.float64)
    if arr.shape == (3,) or (arr.ndim == 2 and arr.shape[1] == 3):
        return arr
    raise ValueError(f"expected {name} of shape (3,) or (N, 3), got shape {arr.shape}")


# --------------------------------------------------------------------------- public API


def quaternion_multiply(q1: ArrayLike, q2: ArrayLike) -> NDArray[np.float64]:
    """Hamilton product ``q1 * q2`` (apply ``q2`` first, then ``q1``), shape (4,)."""
    a = check_quaternion(q1)
    b = check_quaternion(q2)
    return np.array(_qmul(tuple(a), tuple(b)))  # type: ignore[arg-type]


def quaternion_inverse(q: ArrayLike) -> NDArray[np.float64]:
    """Inverse rotation of a unit quaternion (its conjugate), shape (4,)."""
    a = check_quaternion(q)
    return np.array([-a[0], -a[1], -a[2], a[3]])


def matrix_from_quaternion(q: ArrayLike) -> NDArray[np.float64]:
    """Rotation matrix of shape (3, 3) from a quaternion (normalised on the way)."""
    a = check_quaternion(q)
    return np.array(_q_to_m(tuple(a)), dtype=np.float64).reshape(3, 3)  # type: ignore[arg-type]


def quaternion_from_matrix(R: ArrayLike) -> NDArray[np.float64]:
    """Quaternion ``(x, y, z, w)`` of a rotation matrix of shape (3, 3).

    The sign is tf2's (``Matrix3x3::getRotation``): ``w > 0`` when the trace is
    positive, otherwise the component of the largest diagonal element is positive.
    """
    arr = np.asarray(R, dtype=np.float64)
    if arr.shape != (3, 3):
        raise ValueError(f"expected a rotation matrix of shape (3, 3), got shape {arr.shape}")
    return np.array(_m_to_q(tuple(arr.ravel().tolist())))  # type: ignore[arg-type]


def canonical_quaternion(q: ArrayLike) -> NDArray[np.float64]:
    """The unit quaternion of the same rotation, with tf2's sign (see `quaternion_from_matrix`)."""
    a = check_quaternion(q)
    return np.array(_canonical(tuple(a.tolist())))  # type: ignore[arg-type]


def quaternion_slerp(q0: ArrayLike, q1: ArrayLike, fraction: float) -> NDArray[np.float64]:
    """Spherical linear interpolation along the shortest path, as tf2's ``slerp``.

    ``fraction = 0`` gives ``q0``, ``1`` gives ``q1`` (or ``-q1`` when that is nearer).
    """
    a = check_quaternion(q0)
    b = check_quaternion(q1)
    return np.array(_slerp(tuple(a.tolist()), tuple(b.tolist()), float(fraction)))  # type: ignore[arg-type]


def quaternion_from_euler(roll: float, pitch: float, yaw: float) -> NDArray[np.float64]:
    """Quaternion from roll, pitch, yaw about fixed X, Y, Z axes (tf2's ``setRPY``), radians."""
    return np.array(_q_from_rpy(float(roll), float(pitch), float(yaw)))


def euler_from_quaternion(q: ArrayLike) -> tuple[float, float, float]:
    """``(roll, pitch, yaw)`` in radians about fixed X, Y, Z axes (tf2's ``getRPY``)."""
    a = check_quaternion(q)
    return _rpy_from_m(_q_to_m(tuple(a.tolist())))  # type: ignore[arg-type]


def transform_from_pq(p: ArrayLike, q: ArrayLike) -> NDArray[np.float64]:
    """Homogeneous matrix ``A2B`` of shape (4, 4) from a translation (3,) and quaternion (4,)."""
    pos = np.asarray(p, dtype=np.float64)
    if pos.shape != (3,):
        raise ValueError(f"expected a translation of shape (3,), got shape {pos.shape}")
    A2B = np.eye(4)
    A2B[:3, :3] = matrix_from_quaternion(q)
    A2B[:3, 3] = pos
    return A2B


def pq_from_transform(A2B: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Translation (3,) and tf2-canonical quaternion (4,) of a (4, 4) transform."""
    arr = _check_transform(A2B)
    return arr[:3, 3].copy(), quaternion_from_matrix(arr[:3, :3])


def concat(A2B: ArrayLike, B2C: ArrayLike) -> NDArray[np.float64]:
    """Chain two transforms: returns ``A2C = B2C @ A2B``, shape (4, 4)."""
    return _check_transform(B2C, "B2C") @ _check_transform(A2B, "A2B")


def invert_transform(A2B: ArrayLike) -> NDArray[np.float64]:
    """``B2A`` from ``A2B`` (rigid: transpose the rotation), shape (4, 4)."""
    arr = _check_transform(A2B)
    B2A = np.eye(4)
    R_T = arr[:3, :3].T
    B2A[:3, :3] = R_T
    B2A[:3, 3] = -R_T @ arr[:3, 3]
    return B2A


def apply_transform(A2B: ArrayLike, points_A: ArrayLike) -> NDArray[np.float64]:
    """Map points of shape (3,) or (N, 3) from frame A to frame B (rotation and translation)."""
    arr = _check_transform(A2B)
    pts = _check_vectors(points_A, "points_A")
    return pts @ arr[:3, :3].T + arr[:3, 3]


def rotate_vectors(A2B: ArrayLike, vectors_A: ArrayLike) -> NDArray[np.float64]:
    """Map free vectors of shape (3,) or (N, 3) from frame A to B: rotation only."""
    arr = _check_transform(A2B)
    vec = _check_vectors(vectors_A, "vectors_A")
    return vec @ arr[:3, :3].T


# --------------------------------------------------------------------------- scalar core


def _qmul(a: Quat, b: Quat) -> Quat:
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by + ay * bw + az * bx - ax * bz,
        aw * bz + az * bw + ax * by - ay * bx,
        aw * bw - ax * bx - ay * by - az * bz,
    )


def _qinv(q: Quat) -> Quat:
    return (-q[0], -q[1], -q[2], q[3])


def _qrot(q: Quat, v: Vec) -> Vec:
    """tf2's ``quatRotate``: ``(q * v) * q^-1``."""
    qx, qy, qz, qw = q
    vx, vy, vz = v
    # q * v (v as a pure quaternion)
    tx = qw * vx + qy * vz - qz * vy
    ty = qw * vy + qz * vx - qx * vz
    tz = qw * vz + qx * vy - qy * vx
    tw = -qx * vx - qy * vy - qz * vz
    # (q * v) * conj(q)
    ix, iy, iz, iw = -qx, -qy, -qz, qw
    return (
        tw * ix + tx * iw + ty * iz - tz * iy,
        tw * iy + ty * iw + tz * ix - tx * iz,
        tw * iz + tz * iw + tx * iy - ty * ix,
    )


def _q_to_m(q: Quat) -> Mat:
    """Row-major rotation matrix (tf2's ``Matrix3x3::setRotation``; scales by 2/|q|^2)."""
    x, y, z, w = q
    d = x * x + y * y + z * z + w * w
    s = 2.0 / d
    xs, ys, zs = x * s, y * s, z * s
    wx, wy, wz = w * xs, w * ys, w * zs
    xx, xy, xz = x * xs, x * ys, x * zs
    yy, yz, zz = y * ys, y * zs, z * zs
    return (
        1.0 - (yy + zz), xy - wz, xz + wy,
        xy + wz, 1.0 - (xx + zz), yz - wx,
        xz - wy, yz + wx, 1.0 - (xx + yy),
    )  # fmt: skip


def _m_to_q(m: Mat) -> Quat:
    """tf2's ``Matrix3x3::getRotation`` (Shepperd's method and its sign)."""
    trace = m[0] + m[4] + m[8]
    if trace > 0.0:
        s = math.sqrt(trace + 1.0)
        w = s * 0.5
        s = 0.5 / s
        return ((m[7] - m[5]) * s, (m[2] - m[6]) * s, (m[3] - m[1]) * s, w)
    if m[0] < m[4]:
        i = 2 if m[4] < m[8] else 1
    else:
        i = 2 if m[0] < m[8] else 0
    j = (i + 1) % 3
    k = (i + 2) % 3
    s = math.sqrt(m[i * 4] - m[j * 4] - m[k * 4] + 1.0)
    temp = [0.0, 0.0, 0.0, 0.0]
    temp[i] = s * 0.5
    s = 0.5 / s
    temp[3] = (m[k * 3 + j] - m[j * 3 + k]) * s
    temp[j] = (m[j * 3 + i] + m[i * 3 + j]) * s
    temp[k] = (m[k * 3 + i] + m[i * 3 + k]) * s
    return (temp[0], temp[1], temp[2], temp[3])


def _canonical(q: Quat) -> Quat:
    """``_m_to_q(_q_to_m(q))``: normalised, with tf2's sign. The common branch (trace > 0) is
    written out with the very same operations, so the result is identical, just cheaper."""
    x, y, z, w = q
    s = 2.0 / (x * x + y * y + z * z + w * w)
    xs, ys, zs = x * s, y * s, z * s
    wx, wy, wz = w * xs, w * ys, w * zs
    xx, xy, xz = x * xs, x * ys, x * zs
    yy, yz, zz = y * ys, y * zs, z * zs
    m0 = 1.0 - (yy + zz)
    m4 = 1.0 - (xx + zz)
    m8 = 1.0 - (xx + yy)
    trace = m0 + m4 + m8
    if trace > 0.0:
        r = math.sqrt(trace + 1.0)
        half = r * 0.5
        r = 0.5 / r
        return ((yz + wx - (yz - wx)) * r, (xz + wy - (xz - wy)) * r, (xy + wz - (xy - wz)) * r, half)
    return _m_to_q((m0, xy - wz, xz + wy, xy + wz, m4, yz - wx, xz - wy, yz + wx, m8))


def _slerp(a: Quat, b: Quat, t: float) -> Quat:
    """tf2's ``Quaternion::slerp`` (shortest path)."""
    dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]
    s = math.sqrt((a[0] * a[0] + a[1] * a[1] + a[2] * a[2] + a[3] * a[3])
                  * (b[0] * b[0] + b[1] * b[1] + b[2] * b[2] + b[3] * b[3]))  # fmt: skip
    c = (-dot if dot < 0 else dot) / s
    theta = math.acos(c if c < 1.0 else 1.0)  # half the angle between the rotations
    if theta == 0.0:
        return a
    d = 1.0 / math.sin(theta)
    s0 = math.sin((1.0 - t) * theta)
    s1 = math.sin(t * theta)
    if dot < 0:
        s1 = -s1
    return (
        (a[0] * s0 + b[0] * s1) * d,
        (a[1] * s0 + b[1] * s1) * d,
        (a[2] * s0 + b[2] * s1) * d,
        (a[3] * s0 + b[3] * s1) * d,
    )


def _q_from_rpy(roll: float, pitch: float, yaw: float) -> Quat:
    hy, hp, hr = yaw * 0.5, pitch * 0.5, roll * 0.5
    cy, sy = math.cos(hy), math.sin(hy)
    cp, sp = math.cos(hp), math.sin(hp)
    cr, sr = math.cos(hr), math.sin(hr)
    return (
        sr * cp * cy - cr * sp * sy,
        cr * sp * cy + sr * cp * sy,
        cr * cp * sy - sr * sp * cy,
        cr * cp * cy + sr * sp * sy,
    )


def _rpy_from_m(m: Mat) -> tuple[float, float, float]:
    """tf2's ``Matrix3x3::getRPY`` (first solution).

    At gimbal lock (pitch = +-90 deg, within 1e-12 of it) only roll -+ yaw is
    observable: yaw is set to 0 and roll carries the rotation, read from the
    first matrix row (tf2 reads the third row there, which is numerically empty).
    """
    if abs(m[6]) >= 1.0 - 1e-12:
        if m[6] < 0:  # pitch +90 deg: row 0 is (0, sin(roll - yaw), cos(roll - yaw))
            return (math.atan2(m[1], m[2]), math.pi / 2.0, 0.0)
        # pitch -90 deg: row 0 is (0, -sin(roll + yaw), -cos(roll + yaw))
        return (math.atan2(-m[1], -m[2]), -math.pi / 2.0, 0.0)
    pitch = -math.asin(m[6])
    cp = math.cos(pitch)
    roll = math.atan2(m[7] / cp, m[8] / cp)
    yaw = math.atan2(m[3] / cp, m[0] / cp)
    return (roll, pitch, yaw)


def _compose(t1: Vec, q1: Quat, t2: Vec, q2: Quat) -> tuple[Vec, Quat]:
    """``(t1, q1) * (t2, q2)``: apply the second, then the first."""
    r = _qrot(q1, t2)
    return (r[0] + t1[0], r[1] + t1[1], r[2] + t1[2]), _qmul(q1, q2)


def _invert(t: Vec, q: Quat) -> tuple[Vec, Quat]:
    qi = _qinv(q)
    r = _qrot(qi, (-t[0], -t[1], -t[2]))
    return r, qi
