"""robot_localization inputs (``odomN``, ``imuN``, ``poseN``, ``twistN``) to state-space measurements.

Pure functions on numpy arrays: a node reads the message fields, these check them and build
:class:`~aiorobot.fusion.Measurement` objects as robot_localization's ``RosFilter`` does
(``_config`` update vector, ``_differential``, ``_relative``, rejection thresholds, gravity removal).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from ._timeline import Measurement

__all__ = ["InputConfig", "InputRejected", "PoseTracker", "pose_measurement", "twist_measurement", "imu_measurements", "check_message_covariance", "rotation_from_quaternion", "rpy_from_rotation"]

KINDS = ("odom", "imu", "pose", "twist")


class InputRejected(Exception):
    """A message that cannot be used; ``args[0]`` says why (counted per input and reason)."""


@dataclass
class InputConfig:
    """One robot_localization input: ``<name>``, ``<name>_config`` and friends."""

    name: str  # e.g. "odom0"
    kind: str  # odom | imu | pose | twist
    topic: str
    config: NDArray[np.bool_]  # (15,)
    differential: bool = False
    relative: bool = False
    queue_size: int = 10
    pose_threshold: float = math.inf
    twist_threshold: float = math.inf
    acceleration_threshold: float = math.inf
    remove_gravitational_acceleration: bool = False
    gravitational_acceleration: float = 9.80665

    def __post_init__(self) -> None:
        c = np.asarray(self.config, dtype=bool)
        self.config = c
        self.uses_any = bool(c.any())
        self.uses_pose = bool(c[:6].any())
        self.uses_twist = bool(c[6:12].any())


@dataclass
class PoseTracker:
    """Per-input memory for ``_relative`` (first pose) and ``_differential`` (previous pose)."""

    first: NDArray[np.float64] | None = None  # 4x4
    previous: NDArray[np.float64] | None = None  # 4x4
    previous_covariance: NDArray[np.float64] | None = None
    previous_stamp_sec: float = -math.inf
    extra: dict[str, float] = field(default_factory=dict)


def rotation_from_quaternion(x: float, y: float, z: float, w: float) -> NDArray[np.float64]:
    n = math.sqrt(x * x + y * y + z * z + w * w)
    if not math.isfinite(n) or n < 1e-9:
        raise InputRejected(f"orientation quaternion has norm {n:.3g}, expected 1")
    x, y, z, w = x / n, y / n, z / n, w / n
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def rpy_from_rotation(R: NDArray[np.float64]) -> tuple[float, float, float]:
    pitch = math.asin(max(-1.0, min(1.0, -R[2, 0])))
    roll = math.atan2(R[2, 1], R[2, 2])
    yaw = math.atan2(R[1, 0], R[0, 0])
    return roll, pitch, yaw


_COVARIANCE_PROBLEMS = {1: "has NaN or inf", 2: "is not symmetric", 3: "is not positive semi-definite"}


def check_message_covariance(what: str, values: object, size: int) -> NDArray[np.float64]:
    """A row-major ``size x size`` covariance: finite, symmetric, positive semi-definite."""
    from ._kernels import covariance_status

    # a writable copy: a message's read-only array would select a second compiled version of the kernel
    arr = np.array(values, dtype=np.float64).reshape(-1)
    if arr.size != size * size:
        raise InputRejected(f"{what} covariance has {arr.size} values, expected {size * size}")
    C = arr.reshape(size, size)
    status = covariance_status(C)
    if status:
        raise InputRejected(f"{what} covariance {_COVARIANCE_PROBLEMS[status]}")
    return C


def _finite6(what: str, a: NDArray[np.float64], b: NDArray[np.float64]) -> None:
    if not (math.isfinite(a.sum()) and math.isfinite(b.sum())):
        raise InputRejected(f"{what} has NaN or inf")


def _finite(what: str, values: NDArray[np.float64]) -> None:
    if not np.all(np.isfinite(values)):
        raise InputRejected(f"{what} has NaN or inf")


def _blank(stamp: float, source: str, threshold: float) -> Measurement:
    return Measurement(stamp, source, np.zeros(15), np.zeros((15, 15)), np.zeros(15, bool), threshold)


def pose_measurement(
    cfg: InputConfig,
    tracker: PoseTracker,
    stamp_sec: float,
    position: NDArray[np.float64],
    quaternion: NDArray[np.float64],
    covariance: object,
) -> Measurement | None:
    """The pose part of an ``odomN``/``poseN`` message (world frame). ``None`` when nothing to apply yet.

    ``_relative``: poses are taken relative to the input's first pose. ``_differential``: consecutive
    poses become a body-frame velocity ``delta / dt`` with covariance ``(C_prev + C) / dt**2``
    applied to the velocity members selected by the pose booleans, as robot_localization does.
    """
    mask6 = cfg.config[:6]
    if not cfg.uses_pose:
        return None
    _finite6(f"{cfg.name} pose", position, quaternion)
    C = check_message_covariance(f"{cfg.name} pose", covariance, 6)
    T = np.eye(4)
    T[:3, :3] = rotation_from_quaternion(*quaternion)
    T[:3, 3] = position
    if cfg.relative:
        if tracker.first is None:
            tracker.first = T.copy()
        T = np.linalg.inv(tracker.first) @ T
    if cfg.differential:
        previous, previous_cov, previous_stamp = tracker.previous, tracker.previous_covariance, tracker.previous_stamp_sec
        tracker.previous, tracker.previous_covariance, tracker.previous_stamp_sec = T, C, stamp_sec
        if previous is None or previous_cov is None:
            return None
        dt = stamp_sec - previous_stamp
        if dt <= 1e-9:
            raise InputRejected(f"{cfg.name} differential pose does not advance in time")
        delta = np.linalg.inv(previous) @ T
        values = np.concatenate([delta[:3, 3], rpy_from_rotation(delta[:3, :3])]) / dt
        m = _blank(stamp_sec, cfg.name + "_pose", cfg.pose_threshold)
        m.z[6:12] = values
        m.covariance[6:12, 6:12] = (previous_cov + C) / (dt * dt)
        m.mask[6:12] = mask6
        return m
    m = _blank(stamp_sec, cfg.name + "_pose", cfg.pose_threshold)
    m.z[:3] = T[:3, 3]
    m.z[3:6] = rpy_from_rotation(T[:3, :3])
    m.covariance[:6, :6] = C
    m.mask[:6] = mask6
    return m


def twist_measurement(
    cfg: InputConfig, stamp_sec: float, linear: NDArray[np.float64], angular: NDArray[np.float64], covariance: object
) -> Measurement | None:
    """The twist part of an ``odomN``/``twistN`` message (body frame)."""
    mask6 = cfg.config[6:12]
    if not cfg.uses_twist:
        return None
    _finite6(f"{cfg.name} twist", linear, angular)
    C = check_message_covariance(f"{cfg.name} twist", covariance, 6)
    m = _blank(stamp_sec, cfg.name + "_twist", cfg.twist_threshold)
    m.z[6:9] = linear
    m.z[9:12] = angular
    m.covariance[6:12, 6:12] = C
    m.mask[6:12] = mask6
    return m


def imu_measurements(
    cfg: InputConfig,
    tracker: PoseTracker,
    stamp_sec: float,
    quaternion: NDArray[np.float64],
    orientation_covariance: object,
    angular_velocity: NDArray[np.float64],
    angular_velocity_covariance: object,
    linear_acceleration: NDArray[np.float64],
    linear_acceleration_covariance: object,
    base_from_imu: NDArray[np.float64] | None = None,
) -> list[Measurement]:
    """Orientation, angular velocity and linear acceleration parts of an ``imuN`` message.

    ``base_from_imu`` (3x3) rotates the IMU's frame into the base frame (identity when ``None``). An
    orientation covariance whose first element is -1 (sensor_msgs/Imu: "no orientation") drops that part.
    """
    out: list[Measurement] = []
    Rb = np.eye(3) if base_from_imu is None else base_from_imu
    orientation_cfg = cfg.config[3:6]
    ocov = np.asarray(orientation_covariance, dtype=np.float64).reshape(-1)
    world_from_imu: NDArray[np.float64] | None = None
    if (orientation_cfg.any() or cfg.remove_gravitational_acceleration) and not (ocov.size and ocov[0] == -1.0):
        _finite(f"{cfg.name} orientation", quaternion)
        world_from_imu = rotation_from_quaternion(*quaternion)
    if orientation_cfg.any() and world_from_imu is not None:
        C = check_message_covariance(f"{cfg.name} orientation", ocov, 3)
        world_from_base = world_from_imu @ Rb.T
        if cfg.relative:
            if tracker.first is None:
                tracker.first = world_from_base.copy()
            world_from_base = tracker.first.T @ world_from_base
        rpy = np.array(rpy_from_rotation(world_from_base))
        if cfg.differential:
            previous = tracker.previous
            previous_stamp = tracker.previous_stamp_sec
            tracker.previous, tracker.previous_stamp_sec = world_from_base, stamp_sec
            if previous is not None and stamp_sec - previous_stamp > 1e-9:
                dt = stamp_sec - previous_stamp
                m = _blank(stamp_sec, cfg.name + "_pose", cfg.pose_threshold)
                m.z[9:12] = np.array(rpy_from_rotation(previous.T @ world_from_base)) / dt
                m.covariance[9:12, 9:12] = 2.0 * Rb @ C @ Rb.T / (dt * dt)
                m.mask[9:12] = orientation_cfg
                out.append(m)
        else:
            m = _blank(stamp_sec, cfg.name + "_pose", cfg.pose_threshold)
            m.z[3:6] = rpy
            m.covariance[3:6, 3:6] = Rb @ C @ Rb.T
            m.mask[3:6] = orientation_cfg
            out.append(m)
    if cfg.config[9:12].any():
        _finite(f"{cfg.name} angular_velocity", angular_velocity)
        C = check_message_covariance(f"{cfg.name} angular_velocity", angular_velocity_covariance, 3)
        m = _blank(stamp_sec, cfg.name + "_twist", cfg.twist_threshold)
        m.z[9:12] = Rb @ angular_velocity
        m.covariance[9:12, 9:12] = Rb @ C @ Rb.T
        m.mask[9:12] = cfg.config[9:12]
        out.append(m)
    if cfg.config[12:15].any():
        _finite(f"{cfg.name} linear_acceleration", linear_acceleration)
        C = check_message_covariance(f"{cfg.name} linear_acceleration", linear_acceleration_covariance, 3)
        acc = Rb @ linear_acceleration
        if cfg.remove_gravitational_acceleration:
            if world_from_imu is None:
                raise InputRejected(f"{cfg.name} has no orientation to remove gravity with")
            acc = acc - (world_from_imu @ Rb.T).T @ np.array([0.0, 0.0, cfg.gravitational_acceleration])
        m = _blank(stamp_sec, cfg.name + "_acceleration", cfg.acceleration_threshold)
        m.z[12:15] = acc
        m.covariance[12:15, 12:15] = Rb @ C @ Rb.T
        m.mask[12:15] = cfg.config[12:15]
        out.append(m)
    return out
