"""Generated message classes: defaults, construction, equality, repr, constants."""

from __future__ import annotations

import copy
import pickle

import numpy as np
import pytest

import aiorobot.msgs as msgs
from aiorobot.msgs._classgen import _walk
from aiorobot.msgs._registry import all_names

LISTED_PACKAGES = {
    "builtin_interfaces", "std_msgs", "geometry_msgs", "sensor_msgs", "nav_msgs", "tf2_msgs",
    "rosgraph_msgs", "std_srvs", "example_interfaces", "action_msgs", "unique_identifier_msgs",
    "lifecycle_msgs", "diagnostic_msgs", "rcl_interfaces", "service_msgs", "visualization_msgs",
}


def _message_classes(name: str) -> list[type]:
    return [c for c in _walk(msgs.get(name)) if issubclass(c, msgs.Message)]


ALL_MESSAGE_CLASSES = [c for n in all_names(registered=False) for c in _message_classes(n)]


def test_every_listed_package_has_interfaces() -> None:
    packages = {n.split("/")[0] for n in all_names(registered=False)}
    assert LISTED_PACKAGES <= packages


@pytest.mark.parametrize("cls", ALL_MESSAGE_CLASSES, ids=lambda c: c.__msgtype__)
def test_every_type_constructs_with_no_arguments_and_round_trips(cls: type) -> None:
    msg = cls()
    assert msg == cls()
    assert msgs.deserialize(msgs.serialize(msg), cls) == msg
    assert cls.__msgtype__.split("/")[1] in ("msg", "srv", "action")
    assert not hasattr(msg, "__dict__")  # __slots__ only
    assert repr(msg).startswith(cls.__msgtype__.replace("/", ".") + "(")


def test_defaults_are_zeros_empty_strings_and_numpy_arrays() -> None:
    from aiorobot.msgs.sensor_msgs import CameraInfo, Image, JointState

    image = Image()
    assert (image.height, image.encoding, image.header.frame_id) == (0, "", "")
    assert isinstance(image.data, np.ndarray) and image.data.dtype == np.uint8
    assert image.data.shape == (0,)
    info = CameraInfo()
    assert info.k.dtype == np.float64 and info.k.shape == (9,) and not info.k.any()
    assert info.p.shape == (12,)
    assert JointState().name == [] and JointState().position.shape == (0,)
    assert msgs.get("std_msgs/msg/Bool")().data is False
    assert msgs.get("std_msgs/msg/Float64")().data == 0.0


def test_quaternion_defaults_to_identity_as_in_ros2() -> None:
    from aiorobot.msgs.geometry_msgs import Quaternion, TransformStamped

    assert (Quaternion().x, Quaternion().w) == (0.0, 1.0)
    assert TransformStamped().transform.rotation.w == 1.0


def test_fixed_array_of_messages_defaults_to_distinct_default_messages() -> None:
    spec_cls = msgs.register_msg("geometry_msgs/Point[3] corners\nstring[2] names",
                                 "test_msgs_classes/msg/Triangle")
    tri = spec_cls()
    assert len(tri.corners) == 3 and tri.corners[0] is not tri.corners[1]
    assert tri.names == ["", ""]


def test_keyword_and_positional_construction() -> None:
    from aiorobot.msgs.geometry_msgs import Twist, Vector3

    by_kw = Twist(linear=Vector3(x=1.0), angular=Vector3(z=0.5))
    by_pos = Twist(Vector3(1.0, 0.0, 0.0), Vector3(0.0, 0.0, 0.5))
    assert by_kw == by_pos
    assert by_kw.linear.x == 1.0 and by_kw.angular.z == 0.5
    with pytest.raises(TypeError):
        Twist(linaer=Vector3())


def test_numeric_sequences_accept_lists_and_bytes() -> None:
    from aiorobot.msgs.sensor_msgs import Image, LaserScan

    assert Image(data=b"\x01\x02").data.tolist() == [1, 2]
    scan = LaserScan(ranges=[1, 2.5])
    assert scan.ranges.dtype == np.float32 and scan.ranges.tolist() == [1.0, 2.5]
    image = np.zeros((2, 3), np.uint8)
    assert Image(data=image).data.shape == (6,)


def test_fixed_array_with_wrong_length_is_rejected_naming_the_field() -> None:
    from aiorobot.msgs.sensor_msgs import CameraInfo

    with pytest.raises(ValueError, match=r"sensor_msgs/msg/CameraInfo.k is a fixed array of 9 "
                       r"elements, got 4"):
        CameraInfo(k=[1, 2, 3, 4])


def test_equality_compares_values_including_arrays() -> None:
    from aiorobot.msgs.sensor_msgs import JointState

    a = JointState(name=["j1"], position=[1.0, 2.0])
    b = JointState(name=["j1"], position=np.array([1.0, 2.0]))
    assert (a == b) is True
    assert (a != b) is False
    b.position[1] = 3.0
    assert (a == b) is False
    assert a != JointState(name=["j2"], position=[1.0, 2.0])
    assert a != "not a message"


def test_mutable_defaults_are_not_shared_between_instances() -> None:
    from aiorobot.msgs.geometry_msgs import PoseArray
    from aiorobot.msgs.sensor_msgs import CameraInfo, JointState

    a, b = JointState(), JointState()
    a.name.append("x")
    assert b.name == []
    a.header.frame_id = "base"
    assert b.header.frame_id == ""
    c, d = CameraInfo(), CameraInfo()
    c.k[0] = 5.0
    assert d.k[0] == 0.0
    p, q = PoseArray(), PoseArray()
    p.poses.append(None)
    assert q.poses == []


def test_constants_are_class_attributes() -> None:
    from aiorobot.msgs.action_msgs import GoalStatus
    from aiorobot.msgs.visualization_msgs import Marker

    assert GoalStatus.STATUS_SUCCEEDED == 4
    assert GoalStatus.STATUS_ABORTED == 6
    assert Marker.DELETEALL == 3
    assert GoalStatus().STATUS_CANCELED == 5


def test_msgtype_and_module_names() -> None:
    from aiorobot.msgs.geometry_msgs import Twist

    assert Twist.__msgtype__ == "geometry_msgs/msg/Twist"
    assert Twist.__module__ == "aiorobot.msgs.geometry_msgs"
    assert Twist.get_fields_and_field_types() == {"linear": "geometry_msgs/msg/Vector3",
                                                  "angular": "geometry_msgs/msg/Vector3"}


def test_repr_is_readable() -> None:
    from aiorobot.msgs.geometry_msgs import Vector3

    assert repr(Vector3(x=1.5)) == "geometry_msgs.msg.Vector3(x=1.5, y=0.0, z=0.0)"


def test_messages_are_unhashable_because_mutable() -> None:
    from aiorobot.msgs.std_msgs import Header

    with pytest.raises(TypeError):
        hash(Header())


def test_pickle_and_deepcopy_preserve_values() -> None:
    from aiorobot.msgs.example_interfaces import AddTwoInts
    from aiorobot.msgs.sensor_msgs import JointState

    msg = JointState(name=["a"], position=[1.0])
    assert pickle.loads(pickle.dumps(msg)) == msg
    clone = copy.deepcopy(msg)
    assert clone == msg and clone.position is not msg.position
    req = AddTwoInts.Request(a=1, b=2)
    assert pickle.loads(pickle.dumps(req)) == req


def test_time_to_msg_builds_builtin_interfaces_time() -> None:
    import aiorobot
    from aiorobot.msgs.builtin_interfaces import Time

    msg = aiorobot.Time(seconds=3, nanoseconds=5).to_msg()
    assert msg == Time(sec=3, nanosec=5)


def test_messages_support_positional_pattern_matching() -> None:
    from aiorobot.msgs.geometry_msgs import Vector3

    match Vector3(1.0, 2.0, 3.0):
        case Vector3(x, y, z):
            assert (x, y, z) == (1.0, 2.0, 3.0)
        case _:
            pytest.fail("Vector3 did not match")
