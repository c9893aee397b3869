"""Type hashes (RIHS01) and message definitions; generated files are up to date."""

from __future__ import annotations

import ast

import pytest

import aiorobot.msgs as msgs
from aiorobot.msgs._jazzy import DEFS

from ._helpers import rosbags_store

# rosbags types .msg ``char`` as CHAR (13); rosidl maps it to uint8, which changes these hashes
# (INTEROP.md section 7.4).
_CHAR_AFFECTED = {
    "std_msgs/msg/Char", "service_msgs/msg/ServiceEventInfo", "rmw_dds_common/msg/Gid",
    "rmw_dds_common/msg/NodeEntitiesInfo", "rmw_dds_common/msg/ParticipantEntitiesInfo",
}


def test_type_hash_of_string_matches_ros2() -> None:
    from aiorobot.msgs.std_msgs import String

    expected = "RIHS01_df668c740482bbd48fb39d76a70dfd4bd59db1288021743503259e948f6b1a18"
    assert msgs.type_hash(String) == expected
    assert msgs.type_hash("std_msgs/msg/String") == expected


def test_type_hash_of_add_two_ints_service_matches_rmw_zenoh_design_doc() -> None:
    assert msgs.type_hash("example_interfaces/srv/AddTwoInts") == (
        "RIHS01_e118de6bf5eeb66a2491b5bda11202e7b68f198d6f67922cf30364858239c81a")


def test_fibonacci_action_service_hashes() -> None:
    # golden values published with an independent RIHS01 implementation checked against ROS 2
    from aiorobot.msgs.example_interfaces import Fibonacci

    assert msgs.type_hash(Fibonacci.SendGoal) == (
        "RIHS01_d1a57fb2a4afe8c21e34fb10db206f16ce6729b28531141472df92277c55b557")
    assert msgs.type_hash(Fibonacci.GetResult) == (
        "RIHS01_1b0de0d5d29dc955d92f546706568428632771db13ec84c15ec1c1a59f424a57")
    assert msgs.type_hash(Fibonacci) != msgs.type_hash(Fibonacci.SendGoal)


@pytest.mark.parametrize("name", sorted(set(DEFS) - _CHAR_AFFECTED))
def test_message_hashes_match_rosbags(name: str) -> None:
    assert msgs.type_hash(name) == rosbags_store().hash_rihs01(name)


@pytest.mark.parametrize("name", sorted(DEFS))
def test_message_definitions_match_rosbags(name: str) -> None:
    assert msgs.message_definition(name) == rosbags_store().generate_msgdef(name, ros_version=2)[0]


def test_message_definition_lists_dependencies_after_separators() -> None:
    text = msgs.message_definition("geometry_msgs/msg/TwistStamped")
    assert text.startswith("std_msgs/Header header\ngeometry_msgs/Twist twist\n")
    assert f"{'=' * 80}\nMSG: std_msgs/Header\n" in text
    assert "MSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec\n" in text


def test_message_definition_of_a_service_is_a_type_error() -> None:
    with pytest.raises(TypeError, match=r"std_srvs/srv/Trigger is a service"):
        msgs.message_definition("std_srvs/srv/Trigger")


def test_snapshot_matches_the_installed_rosbags_store() -> None:
    from aiorobot.msgs._snapshot import snapshot

    assert snapshot() == DEFS


def test_generated_package_modules_and_stubs_are_up_to_date() -> None:
    from aiorobot.msgs._stubgen import generate

    for path, text in generate(write=False).items():
        assert path.read_text() == text, f"{path.name} is stale: run python -m aiorobot.msgs._stubgen"
        ast.parse(text, filename=path.name)
