"""The buffer core, rule by rule, from tf2's documented BufferCore behaviour. No runtime needed."""

from __future__ import annotations

import logging
import math
import re
import threading

import pytest
from _tf_helpers import IDENTITY, q_of, sec_of, stamp, tf, xyz_of, yaw_q

from aiorobot import Time
from aiorobot.tf import (
    Buffer,
    ConnectivityException,
    ExtrapolationException,
    InvalidArgumentException,
    LookupException,
    TransformException,
)

T = Time  # short alias in tables


def approx(values, abs=1e-9):
    return pytest.approx(values, abs=abs)


@pytest.fixture
def robot() -> Buffer:
    """map -> odom (static) -> base_link (dynamic, 1..3 s) -> lidar_link / camera_link (static)."""
    b = Buffer()
    b.set_transform(tf("map", "odom", 0, (1.0, 0.0, 0.0)), "test", static=True)
    for sec, x in ((1, 0.0), (2, 1.0), (3, 2.0)):
        b.set_transform(tf("odom", "base_link", sec, (x, 0.0, 0.0)), "odometry")
    b.set_transform(tf("base_link", "lidar_link", 0, (0.2, 0.0, 0.3)), "test", static=True)
    b.set_transform(tf("base_link", "camera_link", 0, (0.0, 0.1, 0.5), yaw_q(math.pi / 2)), "test", static=True)
    return b


# ----------------------------------------------------------------------------- tree walks


def test_chain_lookup_composes_every_link(robot):
    out = robot.lookup_transform("map", "lidar_link", T(seconds=2))
    assert xyz_of(out) == approx((1.0 + 1.0 + 0.2, 0.0, 0.3))
    assert q_of(out) == approx(IDENTITY)


def test_lookup_result_names_target_as_parent_and_source_as_child(robot):
    out = robot.lookup_transform("map", "lidar_link", T(seconds=2))
    assert out.header.frame_id == "map"
    assert out.child_frame_id == "lidar_link"
    assert out.header.stamp == stamp(2)
    assert out.__msgtype__ == "geometry_msgs/msg/TransformStamped"


def test_lookup_down_the_tree_is_the_inverse(robot):
    up = robot.lookup_transform("map", "camera_link", T(seconds=2))
    down = robot.lookup_transform("camera_link", "map", T(seconds=2))
    # camera is rotated 90 deg: map's origin seen from the camera
    # camera in map: p = (2.0, 0.1, 0.5), yaw 90 deg; map origin in camera = R^T (-p)
    assert xyz_of(up) == approx((2.0, 0.1, 0.5))
    assert xyz_of(down) == approx((-0.1, 2.0, -0.5))
    assert q_of(down) == approx((0.0, 0.0, -math.sin(math.pi / 4), math.cos(math.pi / 4)))


def test_siblings_are_reached_through_their_common_parent(robot):
    out = robot.lookup_transform("camera_link", "lidar_link", T(seconds=1))
    # lidar origin in base (0.2, 0, 0.3) -> relative to camera (0.2, -0.1, -0.2), rotated by -90 deg
    assert xyz_of(out) == approx((-0.1, -0.2, -0.2))


def test_source_parent_of_target_and_target_parent_of_source(robot):
    assert xyz_of(robot.lookup_transform("base_link", "lidar_link", T(seconds=1))) == approx((0.2, 0.0, 0.3))
    assert xyz_of(robot.lookup_transform("lidar_link", "base_link", T(seconds=1))) == approx((-0.2, 0.0, -0.3))


def test_unknown_frame_raises_lookup_exception_naming_frame_and_argument(robot):
    with pytest.raises(LookupException, match=r'^"nowhere" passed to lookup_transform argument source_frame does not exist\.'):
        robot.lookup_transform("map", "nowhere", T())
    with pytest.raises(LookupException, match=r'^"nowhere" passed to lookup_transform argument target_frame does not exist\.'):
        robot.lookup_transform("nowhere", "map", T())


def test_disconnected_trees_raise_connectivity_exception(robot):
    robot.set_transform(tf("world", "table", 0), "test", static=True)
    with pytest.raises(
        ConnectivityException,
        match=r"^Could not find a connection between 'table' and 'lidar_link' because they are not part of the same tree\.",
    ):
        robot.lookup_transform("table", "lidar_link", T(seconds=2))
    with pytest.raises(ConnectivityException):
        robot.lookup_transform("table", "lidar_link", T())  # through latest-common-time too


def test_all_exceptions_are_transform_exceptions():
    for cls in (LookupException, ConnectivityException, ExtrapolationException, InvalidArgumentException):
        assert issubclass(cls, TransformException)


def test_same_frame_lookup_is_identity_even_for_unknown_frames():
    b = Buffer()
    out = b.lookup_transform("ghost", "ghost", T(seconds=4))
    assert xyz_of(out) == (0.0, 0.0, 0.0)
    assert q_of(out) == IDENTITY
    assert sec_of(out) == 4.0


def test_same_frame_at_time_zero_is_stamped_with_that_frames_latest_data(robot):
    assert sec_of(robot.lookup_transform("base_link", "base_link", T())) == 3.0


# ----------------------------------------------------------------------------- time zero


def test_time_zero_uses_latest_time_common_to_the_chain():
    b = Buffer()
    for sec in (1, 2, 3):
        b.set_transform(tf("odom", "base_link", sec, (sec, 0, 0)), "odometry")
    for sec in (1.0, 2.5):
        b.set_transform(tf("map", "odom", sec, (0, 10 * sec, 0)), "localisation")
    out = b.lookup_transform("map", "base_link", T())
    assert sec_of(out) == 2.5  # map->odom is the older link
    assert xyz_of(out) == approx((2.5, 25.0, 0.0))  # odom->base_link interpolated back to 2.5


def test_static_links_do_not_limit_the_latest_common_time(robot):
    out = robot.lookup_transform("map", "lidar_link", T())
    assert sec_of(out) == 3.0
    assert xyz_of(out) == approx((3.2, 0.0, 0.3))


def test_all_static_chain_at_time_zero_is_stamped_zero(robot):
    out = robot.lookup_transform("lidar_link", "camera_link", T())
    assert sec_of(out) == 0.0


def test_get_latest_common_time(robot):
    assert robot.get_latest_common_time("map", "lidar_link") == T(seconds=3)
    assert robot.get_latest_common_time("lidar_link", "camera_link") == T()
    with pytest.raises(LookupException):
        robot.get_latest_common_time("map", "ghost")


# ----------------------------------------------------------------------------- interpolation


def test_translation_is_interpolated_linearly_and_rotation_by_slerp():
    b = Buffer()
    b.set_transform(tf("odom", "base_link", 10, (0, 0, 0), IDENTITY), "a")
    b.set_transform(tf("odom", "base_link", 11, (4, -2, 1), yaw_q(math.pi / 2)), "a")
    out = b.lookup_transform("odom", "base_link", T(seconds=10.25))
    assert xyz_of(out) == approx((1.0, -0.5, 0.25))
    assert q_of(out) == approx(yaw_q(math.pi / 8))
    assert sec_of(out) == 10.25


def test_slerp_takes_the_short_way_between_opposite_signed_samples():
    b = Buffer()
    b.set_transform(tf("odom", "base_link", 0.5, (0, 0, 0), yaw_q(math.radians(170))), "a")
    # -170 deg, written with negative w: the short way is through 180 deg
    q = yaw_q(math.radians(-170))
    b.set_transform(tf("odom", "base_link", 1.5, (0, 0, 0), tuple(-v for v in q)), "a")
    out = b.lookup_transform("odom", "base_link", T(seconds=1.0))
    x, y, z, w = q_of(out)
    assert abs(w) == approx(0.0)  # a half turn
    assert abs(z) == approx(1.0)


def test_exact_stamp_returns_the_sample():
    b = Buffer()
    b.set_transform(tf("odom", "base_link", 1, (1, 2, 3)), "a")
    b.set_transform(tf("odom", "base_link", 2, (5, 5, 5)), "a")
    assert xyz_of(b.lookup_transform("odom", "base_link", T(seconds=1))) == approx((1, 2, 3))
    assert xyz_of(b.lookup_transform("odom", "base_link", T(seconds=2))) == approx((5, 5, 5))


def test_results_use_tf2s_canonical_rotation_sign():
    b = Buffer()
    # the same rotation as yaw 30 deg, sent with negative w
    b.set_transform(tf("a", "b", 0, (0, 0, 0), tuple(-v for v in yaw_q(math.radians(30)))), "t", static=True)
    out = b.lookup_transform("a", "b", T())
    assert q_of(out) == approx(yaw_q(math.radians(30)))
    assert q_of(out)[3] > 0


# ----------------------------------------------------------------------------- extrapolation


def test_extrapolation_into_the_future_says_so_with_times_and_frames(robot):
    with pytest.raises(ExtrapolationException) as info:
        robot.lookup_transform("map", "lidar_link", T(seconds=3.5))
    assert str(info.value) == (
        "Lookup would require extrapolation into the future.  Requested time 3.500000 but the "
        "latest data is at time 3.000000, when looking up transform from frame [lidar_link] to frame [map]"
    )


def test_extrapolation_into_the_past_says_so_with_times_and_frames(robot):
    with pytest.raises(ExtrapolationException) as info:
        robot.lookup_transform("lidar_link", "map", T(seconds=0.5))
    assert str(info.value) == (
        "Lookup would require extrapolation into the past.  Requested time 0.500000 but the "
        "earliest data is at time 1.000000, when looking up transform from frame [map] to frame [lidar_link]"
    )


def test_a_single_sample_is_valid_only_at_its_stamp():
    b = Buffer()
    b.set_transform(tf("odom", "base_link", 5, (1, 0, 0)), "a")
    assert xyz_of(b.lookup_transform("odom", "base_link", T(seconds=5))) == approx((1, 0, 0))
    with pytest.raises(
        ExtrapolationException,
        match=r"^Lookup would require extrapolation at time 5\.000001, but only time 5\.000000 is in the buffer, "
        r"when looking up transform from frame \[base_link\] to frame \[odom\]$",
    ):
        b.lookup_transform("odom", "base_link", T(seconds=5, nanoseconds=1000))


# ----------------------------------------------------------------------------- statics


def test_static_transforms_are_valid_at_every_time_and_stamped_with_it(robot):
    for sec in (0.001, 12345.0):
        out = robot.lookup_transform("base_link", "lidar_link", T(seconds=sec))
        assert xyz_of(out) == approx((0.2, 0.0, 0.3))
        assert sec_of(out) == approx(sec)


def test_resending_a_static_replaces_it_parent_included(robot):
    robot.set_transform(tf("map", "lidar_link", 0, (9.0, 9.0, 9.0)), "test", static=True)
    assert xyz_of(robot.lookup_transform("map", "lidar_link", T(seconds=1))) == approx((9.0, 9.0, 9.0))
    assert "Frame lidar_link exists with parent map." in robot.all_frames_as_string()


def test_statics_mixed_with_dynamics_interpolate_only_the_dynamic_links(robot):
    out = robot.lookup_transform("map", "camera_link", T(seconds=2.5))
    assert xyz_of(out) == approx((1.0 + 1.5, 0.1, 0.5))
    assert q_of(out) == approx(yaw_q(math.pi / 2))


def test_a_dynamic_insert_replaces_a_static_frame_and_back():
    b = Buffer()
    b.set_transform(tf("a", "b", 0, (1, 0, 0)), "t", static=True)
    b.set_transform(tf("a", "b", 2, (2, 0, 0)), "t")
    with pytest.raises(ExtrapolationException):
        b.lookup_transform("a", "b", T(seconds=1))  # the static value is gone
    b.set_transform(tf("a", "b", 0, (3, 0, 0)), "t", static=True)
    assert xyz_of(b.lookup_transform("a", "b", T(seconds=1))) == approx((3, 0, 0))


def test_clear_forgets_dynamic_data_and_keeps_statics(robot):
    robot.clear()
    assert xyz_of(robot.lookup_transform("base_link", "lidar_link", T(seconds=7))) == approx((0.2, 0.0, 0.3))
    assert not robot.can_transform("odom", "base_link", T(seconds=2))
    robot.set_transform(tf("odom", "base_link", 50, (5, 0, 0)), "odometry")
    assert xyz_of(robot.lookup_transform("map", "lidar_link", T())) == approx((6.2, 0.0, 0.3))


# ----------------------------------------------------------------------------- cache length


def test_samples_older_than_newest_minus_cache_length_are_pruned_at_the_next_insert():
    # geometry2 tf2/src/cache.cpp TimeCache::insertData (Jazzy): prune before inserting, against the
    # newest stamp held before the new sample.
    b = Buffer(cache_time_sec=10.0)
    b.set_transform(tf("odom", "base_link", 100, (0, 0, 0)), "a")
    b.set_transform(tf("odom", "base_link", 105, (5, 0, 0)), "a")
    b.set_transform(tf("odom", "base_link", 110, (10, 0, 0)), "a")
    # exactly newest - cache length: kept
    assert xyz_of(b.lookup_transform("odom", "base_link", T(seconds=100))) == approx((0, 0, 0))
    b.set_transform(tf("odom", "base_link", 110.5, (10.5, 0, 0)), "a")
    # 100 is now older than 110.5 - 10 but survives until the next insert: the boundary still interpolates
    assert xyz_of(b.lookup_transform("odom", "base_link", T(seconds=100.25))) == approx((0.25, 0, 0))
    b.set_transform(tf("odom", "base_link", 111, (11, 0, 0)), "a")
    with pytest.raises(ExtrapolationException, match="earliest data is at time 105.000000"):
        b.lookup_transform("odom", "base_link", T(seconds=100))
    assert xyz_of(b.lookup_transform("odom", "base_link", T(seconds=105))) == approx((5, 0, 0))


def test_an_insert_older_than_the_cache_length_is_refused_with_a_warning(caplog):
    b = Buffer(cache_time_sec=10.0)
    b.set_transform(tf("odom", "base_link", 100, (0, 0, 0)), "odometry")
    with caplog.at_level(logging.WARNING, logger="aiorobot.tf"):
        assert b.set_transform(tf("odom", "base_link", 89.9, (1, 0, 0)), "odometry") is False
    assert "TF_OLD_DATA ignoring data from the past for frame base_link at time 89.900000" in caplog.text
    assert b.set_transform(tf("odom", "base_link", 90, (1, 0, 0)), "odometry") is True
    assert xyz_of(b.lookup_transform("odom", "base_link", T(seconds=90))) == approx((1, 0, 0))


def test_out_of_order_inserts_within_the_cache_are_sorted():
    b = Buffer()
    for sec in (3, 1, 2):
        b.set_transform(tf("odom", "base_link", sec, (sec, 0, 0)), "a")
    assert xyz_of(b.lookup_transform("odom", "base_link", T(seconds=1.5))) == approx((1.5, 0, 0))
    assert xyz_of(b.lookup_transform("odom", "base_link", T(seconds=2.5))) == approx((2.5, 0, 0))


# ----------------------------------------------------------------------------- re-parenting


def test_reparenting_never_interpolates_across_the_parent_change():
    b = Buffer()
    b.set_transform(tf("world", "a", 0, (10, 0, 0)), "t", static=True)
    b.set_transform(tf("world", "b", 0, (0, 20, 0)), "t", static=True)
    b.set_transform(tf("a", "cup", 1, (1, 0, 0)), "gripper")
    b.set_transform(tf("b", "cup", 2, (0, 2, 0)), "table")
    mid = b.lookup_transform("world", "cup", T(seconds=1.5))
    assert xyz_of(mid) == approx((11, 0, 0))  # the older sample, held: still on parent a
    assert xyz_of(b.lookup_transform("world", "cup", T(seconds=2))) == approx((0, 22, 0))
    assert "Frame cup exists with parent b." in b.all_frames_as_string()


# ----------------------------------------------------------------------------- validation


@pytest.mark.parametrize(
    ("msg", "reason"),
    [
        (tf("a", "b", 1, (math.nan, 0, 0)), r"TF_NAN_INPUT: the transform of child \"b\" has NaN or infinite values"),
        (tf("a", "b", 1, (0, 0, 0), (0, 0, 0, math.nan)), r"TF_NAN_INPUT"),
        (tf("a", "b", 1, (math.inf, 0, 0)), r"TF_NAN_INPUT"),
        (tf("a", "b", 1, (0, 0, 0), (0, 0, 0, 1.1)), r"TF_DENORMALIZED_QUATERNION: the rotation of child \"b\" \(0\.0 0\.0 0\.0 1\.1\) has squared norm 1\.21; expected 1 within 0\.01"),
        (tf("a", "b", 1, (0, 0, 0), (0, 0, 0, 0)), r"TF_DENORMALIZED_QUATERNION"),
        (tf("a", "", 1), r"TF_NO_CHILD_FRAME_ID: child_frame_id is empty"),
        (tf("", "b", 1), r"TF_NO_FRAME_ID: header.frame_id of child \"b\" is empty"),
        (tf("/", "b", 1), r"TF_NO_FRAME_ID"),
        (tf("a", "a", 1), r"TF_SELF_TRANSFORM: frame_id and child_frame_id are both \"a\"; a frame cannot be its own parent"),
        (tf("/a", "a", 1), r"TF_SELF_TRANSFORM"),
    ],
)
def test_invalid_inserts_raise_invalid_argument_with_the_reason(msg, reason):
    b = Buffer()
    with pytest.raises(InvalidArgumentException, match=r'^Ignoring transform from authority "me": .*' + reason):
        b.set_transform(msg, "me")
    assert b.get_all_frame_names() == []


def test_nearly_unit_quaternions_are_normalised():
    b = Buffer()
    b.set_transform(tf("a", "b", 1, (0, 0, 0), (0, 0, 0, 1.004)), "me")
    assert q_of(b.lookup_transform("a", "b", T(seconds=1))) == approx(IDENTITY)


def test_set_transform_rejects_non_messages():
    with pytest.raises(InvalidArgumentException, match=r"^expected a geometry_msgs/msg/TransformStamped"):
        Buffer().set_transform({"frame_id": "a"}, "me")


def test_one_leading_slash_is_stripped_on_insert():
    b = Buffer()
    b.set_transform(tf("/map", "/odom", 1, (1, 0, 0)), "ros1 node")
    assert b.get_all_frame_names() == ["odom", "map"]
    assert xyz_of(b.lookup_transform("map", "odom", T(seconds=1))) == approx((1, 0, 0))


@pytest.mark.parametrize(
    ("target", "source", "message"),
    [
        ("/map", "odom", r"^Invalid argument \"/map\" passed to lookup_transform argument target_frame - in tf2 frame_ids cannot start with a '/'"),
        ("map", "/odom", r"^Invalid argument \"/odom\" passed to lookup_transform argument source_frame - in tf2 frame_ids cannot start with a '/'"),
        ("", "odom", r"^Invalid argument \"\" passed to lookup_transform argument target_frame - in tf2 frame_ids cannot be empty$"),
    ],
)
def test_lookups_reject_leading_slashes_and_empty_ids(target, source, message):
    b = Buffer()
    b.set_transform(tf("map", "odom", 1), "me")
    with pytest.raises(InvalidArgumentException, match=message):
        b.lookup_transform(target, source, T(seconds=1))


def test_times_must_be_time_objects_or_messages(robot):
    out = robot.lookup_transform("map", "lidar_link", stamp(2))  # builtin_interfaces/Time
    assert sec_of(out) == 2.0
    with pytest.raises(TypeError, match=r"^expected an aiorobot.Time or a builtin_interfaces/msg/Time message, got float 2.0"):
        robot.lookup_transform("map", "lidar_link", 2.0)


# ----------------------------------------------------------------------------- invalid trees


def test_a_loop_raises_lookup_exception_saying_the_tree_is_invalid():
    b = Buffer()
    b.set_transform(tf("a", "b", 0), "t", static=True)
    b.set_transform(tf("b", "a", 0), "t", static=True)
    b.set_transform(tf("x", "c", 0), "t", static=True)
    with pytest.raises(LookupException, match=r"^The tf tree is invalid because it contains a loop"):
        b.lookup_transform("c", "a", T(seconds=1))
    with pytest.raises(LookupException, match=r"^The tf tree is invalid"):
        b.lookup_transform("c", "a", T())


def test_paths_deeper_than_1000_links_are_invalid():
    b = Buffer()
    for i in range(1001):
        b.set_transform(tf(f"f{i}", f"f{i + 1}", 0, (1, 0, 0)), "t", static=True)
    assert xyz_of(b.lookup_transform("f0", "f1000", T())) == approx((1000, 0, 0))
    with pytest.raises(LookupException, match=r"^The tf tree is invalid because it contains a loop or a path deeper than 1000 links"):
        b.lookup_transform("f0", "f1001", T())


# ----------------------------------------------------------------------------- time travel


def test_lookup_transform_full_travels_in_time_through_a_fixed_frame():
    b = Buffer()
    b.set_transform(tf("odom", "base_link", 1, (0, 0, 0)), "odometry")
    b.set_transform(tf("odom", "base_link", 2, (1, 0, 0), yaw_q(math.pi / 2)), "odometry")
    # where is base_link at t=1 seen from base_link at t=2?
    out = b.lookup_transform_full("base_link", T(seconds=2), "base_link", T(seconds=1), "odom")
    assert xyz_of(out) == approx((0.0, 1.0, 0.0))  # 1 m behind, turned 90 deg: on the robot's +y
    assert q_of(out) == approx(yaw_q(-math.pi / 2))
    assert sec_of(out) == 2.0
    assert out.header.frame_id == "base_link" and out.child_frame_id == "base_link"


def test_lookup_transform_full_validates_all_three_frames(robot):
    with pytest.raises(LookupException, match=r'^"nope" passed to lookup_transform_full argument fixed_frame does not exist'):
        robot.lookup_transform_full("map", T(seconds=1), "lidar_link", T(seconds=2), "nope")


def test_lookup_transform_full_raises_extrapolation_for_either_time(robot):
    with pytest.raises(ExtrapolationException):
        robot.lookup_transform_full("base_link", T(seconds=9), "base_link", T(seconds=1), "odom")
    with pytest.raises(ExtrapolationException):
        robot.lookup_transform_full("base_link", T(seconds=2), "base_link", T(seconds=0.5), "odom")


# ----------------------------------------------------------------------------- can_transform


def test_can_transform_never_raises_and_can_say_why(robot):
    assert robot.can_transform("map", "lidar_link", T(seconds=2)) is True
    assert robot.can_transform("map", "lidar_link", T(seconds=2), return_debug_tuple=True) == (True, "")
    cases = {
        ("map", "ghost", T()): r"^\"ghost\" passed to can_transform argument source_frame does not exist",
        ("/map", "odom", T()): r"cannot start with a '/'",
        ("", "odom", T()): r"cannot be empty",
        ("map", "lidar_link", T(seconds=9)): r"^Lookup would require extrapolation into the future",
    }
    for (target, source, time), reason in cases.items():
        assert robot.can_transform(target, source, time) is False
        ok, why = robot.can_transform(target, source, time, return_debug_tuple=True)
        assert ok is False
        assert re.search(reason, why), why


def test_can_transform_of_disconnected_and_looping_trees_is_false():
    b = Buffer()
    b.set_transform(tf("a", "b", 0), "t", static=True)
    b.set_transform(tf("b", "a", 0), "t", static=True)
    b.set_transform(tf("x", "c", 0), "t", static=True)
    assert b.can_transform("x", "c", T()) is True
    assert b.can_transform("c", "a", T()) is False
    b.set_transform(tf("y", "d", 0), "t", static=True)
    ok, why = b.can_transform("c", "d", T(), return_debug_tuple=True)
    assert not ok and why.startswith("Could not find a connection between 'c' and 'd'")


def test_can_transform_same_frame_is_true_even_if_unknown():
    assert Buffer().can_transform("ghost", "ghost", T()) is True


def test_can_transform_full(robot):
    assert robot.can_transform_full("base_link", T(seconds=3), "base_link", T(seconds=1), "odom") is True
    ok, why = robot.can_transform_full(
        "base_link", T(seconds=4), "base_link", T(seconds=1), "odom", return_debug_tuple=True
    )
    assert not ok and "extrapolation into the future" in why
    assert robot.can_transform_full("base_link", T(seconds=3), "base_link", T(seconds=1), "nope") is False


# ----------------------------------------------------------------------------- views


def test_all_frames_as_string_lists_each_frame_and_its_parent(robot):
    assert robot.all_frames_as_string() == (
        "Frame odom exists with parent map.\n"
        "Frame base_link exists with parent odom.\n"
        "Frame lidar_link exists with parent base_link.\n"
        "Frame camera_link exists with parent base_link.\n"
    )


def test_all_frames_as_yaml_gives_parent_broadcaster_rate_and_span(robot):
    text = robot.all_frames_as_yaml()
    assert (
        "base_link: \n"
        "  parent: 'odom'\n"
        "  broadcaster: 'odometry'\n"
        "  rate: 1.500\n"
        "  most_recent_transform: 3.000000\n"
        "  oldest_transform: 1.000000\n"
        "  buffer_length: 2.000\n"
    ) in text
    assert Buffer().all_frames_as_yaml() == "[]"


def test_to_dot_shows_frames_parents_authority_rate_and_latest_stamp(robot):
    dot = robot.to_dot()
    assert dot.startswith("digraph G {\n")
    assert dot.rstrip().endswith("}")
    assert (
        '"odom" -> "base_link" [label="Broadcaster: odometry\\nAverage rate: 1.500 Hz\\n'
        'Most recent transform: 3.000000\\nBuffer length: 2.000 sec"];'
    ) in dot
    assert '"base_link" -> "lidar_link" [label="Broadcaster: test\\nstatic"];' in dot
    for frame in ("map", "odom", "base_link", "lidar_link", "camera_link"):
        assert f'"{frame}";' in dot


def test_to_dot_with_current_time_says_how_old_the_data_is(robot):
    assert "Most recent transform: 3.000000 (1.500 sec old)" in robot.to_dot(T(seconds=4.5))


# ----------------------------------------------------------------------------- threads


def test_concurrent_inserts_and_lookups_from_threads_stay_consistent():
    b = Buffer(cache_time_sec=1000.0)
    b.set_transform(tf("map", "odom", 0), "t", static=True)
    errors: list[BaseException] = []
    start = threading.Barrier(3)

    def writer() -> None:
        start.wait()
        for i in range(1, 2001):
            b.set_transform(tf("odom", "base_link", i * 0.01, (i * 0.01, 0, 0)), "w")

    def reader() -> None:
        start.wait()
        for _ in range(2000):
            try:
                out = b.lookup_transform("map", "base_link", T())
            except TransformException:
                continue  # not there yet
            except BaseException as exc:  # noqa: BLE001 - collected for the assertion
                errors.append(exc)
                return
            if abs(xyz_of(out)[0] - sec_of(out)) > 1e-6:
                errors.append(AssertionError(f"inconsistent {xyz_of(out)} at {sec_of(out)}"))
                return

    threads = [threading.Thread(target=writer), threading.Thread(target=reader), threading.Thread(target=reader)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert errors == []
    assert sec_of(b.lookup_transform("map", "base_link", T())) == approx(20.0)
