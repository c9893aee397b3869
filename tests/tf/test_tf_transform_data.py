"""Transforming stamped messages and point clouds, and the seed scenarios of issue 4."""

from __future__ import annotations

import math

import numpy as np
import pytest
from _tf_helpers import q_of, sec_of, stamp, tf, xyz_of, yaw_q
from numpy.testing import assert_array_almost_equal

from aiorobot import Time
from aiorobot.msgs.geometry_msgs import (
    Point,
    PointStamped,
    Pose,
    PoseStamped,
    Quaternion,
    QuaternionStamped,
    Twist,
    Vector3,
    Vector3Stamped,
)
from aiorobot.msgs.std_msgs import Header
from aiorobot.tf import Buffer, ExtrapolationException, do_transform


@pytest.fixture
def robot() -> Buffer:
    """The seed scenario: static sensor mounts on base_link, odometry odom -> base_link, map -> odom."""
    b = Buffer()
    # static sensor mounts (as a StaticTransformBroadcaster would send them)
    b.set_transform(tf("base_link", "lidar_link", 0, (0.3, 0.0, 0.2), yaw_q(math.pi)), "mounts", static=True)
    b.set_transform(tf("base_link", "imu_link", 0, (0.0, 0.0, 0.1)), "mounts", static=True)
    # odometry: driving +x at 1 m/s while turning to face +y
    b.set_transform(tf("odom", "base_link", 10, (0.0, 0.0, 0.0), yaw_q(0.0)), "ekf")
    b.set_transform(tf("odom", "base_link", 11, (1.0, 0.0, 0.0), yaw_q(math.pi / 2)), "ekf")
    # localisation: odom drifted 0.5 m in y relative to map
    b.set_transform(tf("map", "odom", 9.5, (0.0, 0.5, 0.0)), "localizer")
    b.set_transform(tf("map", "odom", 11.5, (0.0, 0.5, 0.0)), "localizer")
    return b


def header(frame: str, sec: float) -> Header:
    return Header(stamp=stamp(sec), frame_id=frame)


# ----------------------------------------------------------------------------- seed scenarios


def test_seed_lookup_map_to_lidar_goes_through_odom_and_base_link(robot):
    out = robot.lookup_transform("map", "lidar_link", Time(seconds=11))
    # base at (1, 0.5) facing +y; the lidar 0.3 m ahead of it faces backwards (-y)
    assert xyz_of(out) == pytest.approx((1.0, 0.8, 0.2))
    assert q_of(out) == pytest.approx(yaw_q(-math.pi / 2))
    latest = robot.lookup_transform("map", "lidar_link", Time())
    assert sec_of(latest) == 11.0  # odometry is the link with the oldest latest stamp


def test_seed_obstacle_point_from_lidar_into_map(robot):
    obstacle = PointStamped(header=header("lidar_link", 11), point=Point(x=2.0, y=0.0, z=0.0))
    out = robot.transform(obstacle, "map")
    # 2 m in front of a backwards-facing lidar at (1, 0.8): 2 m towards -y
    assert (out.point.x, out.point.y, out.point.z) == pytest.approx((1.0, -1.2, 0.2))
    assert out.header.frame_id == "map"
    assert out.header.stamp == stamp(11)
    assert type(out) is PointStamped
    assert obstacle.header.frame_id == "lidar_link"  # the input is left alone


def test_seed_transform_at_a_time_between_odometry_samples(robot):
    obstacle = PointStamped(header=header("lidar_link", 10.5), point=Point(x=1.0))
    out = robot.transform(obstacle, "map")
    # base at (0.5, 0.5) facing yaw 45 deg, lidar faces 225 deg, 1.3 m from base along 45 deg then back
    c = math.cos(math.pi / 4)
    expected = (0.5 + 0.3 * c - c, 0.5 + 0.3 * c - c, 0.2)
    assert (out.point.x, out.point.y, out.point.z) == pytest.approx(expected)


def test_transform_outside_the_data_raises_extrapolation(robot):
    with pytest.raises(ExtrapolationException):
        robot.transform(PointStamped(header=header("lidar_link", 12)), "map")


# ----------------------------------------------------------------------------- message types


def test_vector3_is_only_rotated(robot):
    out = robot.transform(Vector3Stamped(header=header("base_link", 11), vector=Vector3(x=1.0)), "map")
    assert (out.vector.x, out.vector.y, out.vector.z) == pytest.approx((0.0, 1.0, 0.0))
    assert out.header.frame_id == "map"


def test_pose_position_and_orientation_are_transformed(robot):
    pose = PoseStamped(
        header=header("base_link", 11),
        pose=Pose(position=Point(x=1.0), orientation=Quaternion(x=0.0, y=0.0, z=math.sin(math.pi / 8), w=math.cos(math.pi / 8))),
    )
    out = robot.transform(pose, "odom")
    p, o = out.pose.position, out.pose.orientation
    assert (p.x, p.y, p.z) == pytest.approx((1.0, 1.0, 0.0))
    assert (o.x, o.y, o.z, o.w) == pytest.approx(yaw_q(math.pi / 2 + math.pi / 4))


def test_quaternion_is_rotated(robot):
    q = QuaternionStamped(header=header("base_link", 11), quaternion=Quaternion(x=0.0, y=0.0, z=0.0, w=1.0))
    out = robot.transform(q, "odom")
    r = out.quaternion
    assert (r.x, r.y, r.z, r.w) == pytest.approx(yaw_q(math.pi / 2))


def test_transform_stamped_is_rechained_keeping_its_child(robot):
    mount = tf("lidar_link", "lidar_optical", 11, (0.0, 0.0, 0.05))
    out = robot.transform(mount, "base_link")
    assert out.header.frame_id == "base_link"
    assert out.child_frame_id == "lidar_optical"
    assert xyz_of(out) == pytest.approx((0.3, 0.0, 0.25))
    assert q_of(out) == pytest.approx((0.0, 0.0, 1.0, 0.0))  # canonical sign of a half turn


def test_a_zero_orientation_is_refused_with_the_fix(robot):
    pose = PoseStamped(header=header("base_link", 11), pose=Pose(orientation=Quaternion(x=0.0, y=0.0, z=0.0, w=0.0)))
    with pytest.raises(ValueError, match=r"^the pose's orientation is \(0, 0, 0, 0\), which is no rotation; the identity is \(0, 0, 0, 1\)$"):
        robot.transform(pose, "map")


def test_unsupported_types_say_which_are_supported(robot):
    with pytest.raises(TypeError, match=r"^cannot transform a geometry_msgs/msg/Twist; supported types are geometry_msgs/msg/PointStamped"):
        robot.transform(Twist(), "map")


def test_do_transform_applies_a_looked_up_transform(robot):
    t = robot.lookup_transform("map", "lidar_link", Time(seconds=11))
    out = do_transform(PointStamped(header=header("lidar_link", 11), point=Point(x=2.0)), t)
    assert (out.point.x, out.point.y) == pytest.approx((1.0, -1.2))


async def test_transform_async_waits_for_the_data(robot):
    import asyncio

    msg = PointStamped(header=header("lidar_link", 12), point=Point(x=1.0))
    task = asyncio.create_task(robot.transform_async(msg, "odom", timeout_sec=30.0))
    for _ in range(3):
        await asyncio.sleep(0)
    assert not task.done()
    robot.set_transform(tf("odom", "base_link", 12, (1.0, 1.0, 0.0), yaw_q(math.pi / 2)), "ekf")
    out = await task
    assert (out.point.x, out.point.y) == pytest.approx((1.0, 1.3 - 1.0))


def test_transform_full_travels_in_time(robot):
    # where is the point seen by the lidar at t=10 relative to the robot at t=11?
    msg = PointStamped(header=header("base_link", 10), point=Point(x=1.0))
    out = robot.transform_full(msg, "base_link", Time(seconds=11), "odom")
    assert (out.point.x, out.point.y) == pytest.approx((0.0, 0.0))
    assert out.header.stamp == stamp(11)


# ----------------------------------------------------------------------------- batches


def test_transform_points_matches_the_point_by_point_transform(robot):
    rng = np.random.default_rng(42)
    cloud = rng.uniform(-5, 5, size=(1000, 3))
    out = robot.transform_points(cloud, "map", "lidar_link", Time(seconds=10.5))
    assert out.shape == (1000, 3)
    for i in (0, 1, 500, 999):
        single = robot.transform(
            PointStamped(header=header("lidar_link", 10.5), point=Point(x=cloud[i, 0], y=cloud[i, 1], z=cloud[i, 2])),
            "map",
        )
        assert_array_almost_equal(out[i], [single.point.x, single.point.y, single.point.z])


def test_transform_points_accepts_float32_and_lists_and_returns_float64(robot):
    out = robot.transform_points(np.zeros((2, 3), dtype=np.float32), "base_link", "lidar_link", Time())
    assert out.dtype == np.float64
    assert_array_almost_equal(out, [[0.3, 0.0, 0.2]] * 2)
    assert robot.transform_points([[0.0, 0.0, 0.0]], "base_link", "base_link", Time()).shape == (1, 3)
    assert robot.transform_points(np.empty((0, 3)), "map", "lidar_link", Time()).shape == (0, 3)


def test_transform_points_rejects_bad_shapes(robot):
    with pytest.raises(ValueError, match=r"^expected points of shape \(N, 3\), got shape \(4, 2\)$"):
        robot.transform_points(np.zeros((4, 2)), "map", "lidar_link", Time())
