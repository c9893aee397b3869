"""CDR: byte identity with rosbags, round trips and clear errors on bad bytes."""

from __future__ import annotations

import zlib

import numpy as np
import pytest

import aiorobot.msgs as msgs
from aiorobot.msgs.builtin_interfaces import Time
from aiorobot.msgs.geometry_msgs import (
    Point,
    Pose,
    Quaternion,
    Transform,
    TransformStamped,
    Twist,
    Vector3,
)
from aiorobot.msgs.nav_msgs import Odometry
from aiorobot.msgs.sensor_msgs import Image, JointState, LaserScan, PointCloud2, PointField
from aiorobot.msgs.std_msgs import Header, String
from aiorobot.msgs.tf2_msgs import TFMessage

from ._helpers import random_message, rosbags_store, to_rosbags


def _rosbags_bytes(msg: object) -> bytes:
    store = rosbags_store()
    return bytes(store.serialize_cdr(to_rosbags(msg), msg.__msgtype__, little_endian=True))


def _header(frame: str = "base_link") -> Header:
    return Header(stamp=Time(sec=1_700_000_000, nanosec=123_456_789), frame_id=frame)


REPRESENTATIVE = {
    "twist": Twist(linear=Vector3(x=0.5, y=-0.25), angular=Vector3(z=1.25)),
    "image": Image(header=_header("camera"), height=2, width=3, encoding="rgb8", step=9,
                   data=np.arange(18, dtype=np.uint8)),
    "laser_scan": LaserScan(header=_header("laser"), angle_min=-1.5, angle_max=1.5,
                            angle_increment=0.5, range_min=0.125, range_max=10.0,
                            ranges=np.linspace(0.5, 3.0, 7, dtype=np.float32),
                            intensities=np.ones(7, np.float32)),
    "point_cloud2": PointCloud2(
        header=_header("lidar"), height=1, width=2,
        fields=[PointField(name="x", offset=0, datatype=PointField.FLOAT32, count=1),
                PointField(name="y", offset=4, datatype=PointField.FLOAT32, count=1)],
        is_bigendian=False, point_step=8, row_step=16,
        data=np.arange(16, dtype=np.uint8), is_dense=True),
    "joint_state": JointState(header=_header(), name=["shoulder", "elbow"],
                              position=[0.1, -0.2], velocity=[1.0, 2.0], effort=[]),
    "odometry": Odometry(header=_header("odom"), child_frame_id="base_link",
                         pose=msgs.get("geometry_msgs/msg/PoseWithCovariance")(
                             pose=Pose(position=Point(x=1.0), orientation=Quaternion(w=1.0)),
                             covariance=np.arange(36, dtype=np.float64))),
    "tf_message": TFMessage(transforms=[
        TransformStamped(header=_header("map"), child_frame_id="odom",
                         transform=Transform(translation=Vector3(x=1.0))),
        TransformStamped(header=_header("odom"), child_frame_id="base_link"),
    ]),
    "unicode_string": String(data="héllo wörld ✓ 漢字 🙂"),
    "empty_string": String(data=""),
    "empty_sequences": JointState(),
    "bounded_sequence": msgs.get("rcl_interfaces/msg/ParameterDescriptor")(
        name="gain", floating_point_range=[msgs.get("rcl_interfaces/msg/FloatingPointRange")(
            from_value=0.0, to_value=1.0, step=0.1)]),
    "bounded_float_sequence": msgs.get("shape_msgs/msg/SolidPrimitive")(
        type=1, dimensions=[1.0, 2.0, 3.0]),
    "bounded_string": msgs.get("rmw_dds_common/msg/NodeEntitiesInfo")(
        node_namespace="/ns", node_name="talker"),
    "fixed_arrays": msgs.get("sensor_msgs/msg/CameraInfo")(
        k=np.arange(9.0), r=np.eye(3).ravel(), p=np.arange(12.0), d=[0.1, 0.2]),
    "fixed_uint8_array": msgs.get("unique_identifier_msgs/msg/UUID")(uuid=np.arange(16)),
}


@pytest.mark.parametrize("name", sorted(REPRESENTATIVE))
def test_representative_types_are_byte_identical_to_rosbags(name: str) -> None:
    msg = REPRESENTATIVE[name]
    data = msgs.serialize(msg)
    assert isinstance(data, bytes)
    assert data == _rosbags_bytes(msg)
    assert data[:4] == b"\x00\x01\x00\x00"
    assert msgs.deserialize(data, type(msg)) == msg


def test_twist_encoding_is_the_known_52_bytes() -> None:
    data = msgs.serialize(Twist(linear=Vector3(x=1.0)))
    assert len(data) == 52
    assert data[4:12] == np.float64(1.0).tobytes()


@pytest.mark.parametrize("name", sorted(rosbags_store().fielddefs))
def test_every_jazzy_type_matches_rosbags_on_random_values(name: str) -> None:
    rng = np.random.default_rng(zlib.crc32(name.encode()))
    cls = msgs.get(name)
    for _ in range(5):
        msg = random_message(cls, rng)
        data = msgs.serialize(msg)
        assert data == _rosbags_bytes(msg)
        assert msgs.deserialize(data, name) == msg
        back = rosbags_store().deserialize_cdr(data, name)
        assert type(back).__name__ == name.replace("/", "__")


@pytest.mark.parametrize("name", ["sensor_msgs/msg/Image", "nav_msgs/msg/Odometry",
                                  "visualization_msgs/msg/MarkerArray", "tf2_msgs/msg/TFMessage",
                                  "rcl_interfaces/msg/ParameterEvent"])
def test_big_endian_cdr_is_read(name: str) -> None:
    rng = np.random.default_rng(7)
    msg = random_message(msgs.get(name), rng)
    data = bytes(rosbags_store().serialize_cdr(to_rosbags(msg), name, little_endian=False))
    assert data[:2] == b"\x00\x00"
    back = msgs.deserialize(data, name)
    assert back == msg
    assert msgs.serialize(back) == msgs.serialize(msg)  # arrays came back native-endian


def test_deserialize_accepts_memoryview_bytearray_and_names() -> None:
    msg = REPRESENTATIVE["image"]
    data = msgs.serialize(msg)
    assert msgs.deserialize(memoryview(data), "sensor_msgs/msg/Image") == msg
    assert msgs.deserialize(bytearray(data), "sensor_msgs/Image") == msg


def test_deserialized_arrays_are_writable_copies() -> None:
    data = msgs.serialize(REPRESENTATIVE["image"])
    image = msgs.deserialize(data, Image)
    image.data[0] = 200
    assert msgs.deserialize(data, Image).data[0] == 0


@pytest.mark.parametrize("padding", [b"\x00", b"\x00\x00", b"\x00\x00\x00"])
def test_up_to_three_trailing_padding_bytes_are_tolerated(padding: bytes) -> None:
    msg = String(data="abc")
    assert msgs.deserialize(msgs.serialize(msg) + padding, String) == msg


def test_more_trailing_bytes_mean_the_wrong_type() -> None:
    data = msgs.serialize(Twist())
    with pytest.raises(msgs.DeserializationError,
                       match=r"^cannot deserialize geometry_msgs/msg/Vector3: 24 unexpected bytes "
                             r"after the message \(it ends at byte 28 of 52"):
        msgs.deserialize(data, Vector3)


@pytest.mark.parametrize("name", sorted(REPRESENTATIVE))
def test_every_truncation_raises_deserialization_error(name: str) -> None:
    msg = REPRESENTATIVE[name]
    data = msgs.serialize(msg)
    for end in range(len(data) - 3):  # up to 3 bytes may be padding
        with pytest.raises(msgs.DeserializationError, match=msg.__msgtype__):
            msgs.deserialize(data[:end], type(msg))


def test_truncation_error_names_the_field_and_offset() -> None:
    data = msgs.serialize(REPRESENTATIVE["image"])
    cut = len(data) - 5
    with pytest.raises(msgs.DeserializationError,
                       match=rf"^cannot deserialize sensor_msgs/msg/Image from {cut} bytes: reading "
                             rf"field 'data' at byte {len(data) - 18}: sequence of 18 uint8 needs "
                             r"18 bytes, 13 left$"):
        msgs.deserialize(data[:cut], Image)
    with pytest.raises(msgs.DeserializationError,
                       match=r"reading field 'step', 'data \(length\)' at byte \d+: data ends "
                             r"after \d+ bytes \(truncated\?\)$"):
        msgs.deserialize(data[:len(data) - 20], Image)


def test_garbage_raises_deserialization_error_never_index_or_struct_errors() -> None:
    rng = np.random.default_rng(1234)
    classes = [type(m) for m in REPRESENTATIVE.values()]
    for _ in range(300):
        n = int(rng.integers(0, 200))
        data = b"\x00\x01\x00\x00" + rng.integers(0, 256, n, dtype=np.uint8).tobytes()
        for cls in classes:
            try:
                msgs.deserialize(data, cls)
            except msgs.DeserializationError as exc:
                assert isinstance(exc, ValueError)
                assert cls.__msgtype__ in str(exc)


def test_bad_header_is_reported() -> None:
    with pytest.raises(msgs.DeserializationError, match=r"unsupported CDR encapsulation header "
                                                        r"07 00 00 00"):
        msgs.deserialize(b"\x07\x00\x00\x00" + bytes(48), Twist)
    with pytest.raises(msgs.DeserializationError, match=r"got 2 bytes, too short"):
        msgs.deserialize(b"\x00\x01", Twist)


def test_invalid_utf8_and_missing_terminator_are_reported() -> None:
    bad_utf8 = b"\x00\x01\x00\x00" + (3).to_bytes(4, "little") + b"\xff\xfe\x00"
    with pytest.raises(msgs.DeserializationError, match=r"field 'data'.*UnicodeDecodeError"):
        msgs.deserialize(bad_utf8, String)
    no_nul = b"\x00\x01\x00\x00" + (3).to_bytes(4, "little") + b"abc"
    with pytest.raises(msgs.DeserializationError, match=r"not NUL-terminated"):
        msgs.deserialize(no_nul, String)


def test_bounded_sequence_overflow_is_rejected_both_ways() -> None:
    solid = msgs.get("shape_msgs/msg/SolidPrimitive")(dimensions=[1.0, 2.0, 3.0, 4.0])
    with pytest.raises(msgs.SerializationError, match=r"field 'dimensions' is bounded to 3 "
                                                      r"elements, got 4"):
        msgs.serialize(solid)
    ok = msgs.serialize(msgs.get("shape_msgs/msg/SolidPrimitive")(dimensions=[1.0, 2.0, 3.0]))
    forged = ok[:8] + bytes([4]) + ok[9:] + bytes(8)  # count 3 -> 4
    with pytest.raises(msgs.DeserializationError, match=r"is bounded to 3 elements, got 4"):
        msgs.deserialize(forged, "shape_msgs/msg/SolidPrimitive")


def test_serialization_errors_name_type_and_field() -> None:
    twist = Twist()
    twist.angular.z = "fast"
    with pytest.raises(msgs.SerializationError,
                       match=r"^cannot serialize geometry_msgs/msg/Twist: field 'angular.z' "
                             r"expects float64, got str 'fast'$"):
        msgs.serialize(twist)
    header = Header()
    header.stamp.sec = 2**31  # assignment is not checked; the constructor is (test_field_checks.py)
    with pytest.raises(msgs.SerializationError, match=r"field 'stamp.sec' expects int32 in "
                                                      r"\[-2147483648, 2147483647\], got 2147483648"):
        msgs.serialize(header)
    tf = TFMessage(transforms=[TransformStamped(), TransformStamped()])
    tf.transforms[1].child_frame_id = 5
    with pytest.raises(msgs.SerializationError, match=r"field 'transforms\[1\].child_frame_id'"):
        msgs.serialize(tf)
    with pytest.raises(TypeError, match=r"expects an aiorobot.msgs message instance"):
        msgs.serialize({"linear": 1})


def test_deserialize_rejects_service_types() -> None:
    from aiorobot.msgs.std_srvs import Trigger

    with pytest.raises(TypeError, match=r"use .Request or .Response"):
        msgs.deserialize(b"\x00\x01\x00\x00", Trigger)


def test_wstring_uses_utf16_code_units_like_fast_cdr() -> None:
    from aiorobot.msgs.example_interfaces import WString

    data = msgs.serialize(WString(data="hé🙂"))
    # length counts UTF-16 code units (no terminator), then 2 bytes per unit
    assert data[4:8] == (4).to_bytes(4, "little")
    assert data[8:] == "hé🙂".encode("utf-16-le")
    assert msgs.deserialize(data, WString).data == "hé🙂"


def test_services_and_actions_parts_round_trip() -> None:
    from aiorobot.msgs.example_interfaces import AddTwoInts, Fibonacci

    req = AddTwoInts.Request(a=-3, b=2**40)
    assert msgs.deserialize(msgs.serialize(req), AddTwoInts.Request) == req
    fb = Fibonacci.FeedbackMessage(feedback=Fibonacci.Feedback(sequence=[0, 1, 1, 2]))
    fb.goal_id.uuid[:] = np.arange(16)
    back = msgs.deserialize(msgs.serialize(fb), "example_interfaces/action/Fibonacci_FeedbackMessage")
    assert back == fb


@pytest.mark.parametrize("name", ["sensor_msgs/msg/Image", "nav_msgs/msg/Odometry", "geometry_msgs/msg/Twist",
                                  "tf2_msgs/msg/TFMessage", "sensor_msgs/msg/JointState"])
def test_a_receiver_s_decoder_decodes_and_refuses_as_deserialize_does(name: str) -> None:
    from aiorobot.msgs._cdr import decoder

    cls = msgs.get(name)
    rng = np.random.default_rng(zlib.crc32(name.encode()))
    msg = random_message(cls, rng)
    little = msgs.serialize(msg)
    big = bytes(rosbags_store().serialize_cdr(to_rosbags(msg), name, little_endian=False))
    for view in (False, True):
        decode = decoder(cls, view=view)
        for data in (little, memoryview(little), little + b"\0\0\0", big):
            assert decode(data) == msg == msgs.deserialize(data, cls, view=view)
        for bad in (little[:-5], little + b"\0" * 4, b"\1\1" + little[2:], little[:3]):
            with pytest.raises(msgs.DeserializationError) as expected:
                msgs.deserialize(bad, cls, view=view)
            with pytest.raises(msgs.DeserializationError) as got:
                decode(bad)
            assert str(got.value) == str(expected.value)
        if cls is Image:  # the view form: pixels are read-only views into the received bytes
            assert decode(little).data.flags.writeable is not view
