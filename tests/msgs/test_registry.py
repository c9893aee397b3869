"""Lookup by name, user registration, service and action class structure, package modules."""

from __future__ import annotations

import importlib
from pathlib import Path

import numpy as np
import pytest

import aiorobot.msgs as msgs


def test_module_exposes_all() -> None:
    assert "get" in msgs.__all__ and "serialize" in msgs.__all__
    for name in msgs.__all__:
        assert hasattr(msgs, name), name


def test_get_accepts_full_and_short_names_and_classes() -> None:
    from aiorobot.msgs.sensor_msgs import Image

    assert msgs.get("sensor_msgs/msg/Image") is Image
    assert msgs.get("sensor_msgs/Image") is Image
    assert msgs.get(Image) is Image
    assert msgs.get("std_srvs/srv/Trigger") is msgs.get("std_srvs/Trigger")
    assert msgs.get("example_interfaces/action/Fibonacci").__msgtype__ == (
        "example_interfaces/action/Fibonacci")


def test_get_of_an_unknown_name_suggests_close_names() -> None:
    with pytest.raises(LookupError, match=r"^unknown interface type 'sensor_msgs/msg/Imag'; "
                                          r"did you mean 'sensor_msgs/msg/Image'"):
        msgs.get("sensor_msgs/msg/Imag")
    with pytest.raises(LookupError, match=r"unknown interface type 'nope_msgs/msg/Nothing'; "
                                          r"register it with"):
        msgs.get("nope_msgs/msg/Nothing")
    with pytest.raises(LookupError, match=r"^unknown interface type 'Twist'; did you mean "
                                          r"'geometry_msgs/msg/Twist'\?$"):
        msgs.get("Twist")


def test_parts_of_services_and_actions_are_found_by_name() -> None:
    from aiorobot.msgs.example_interfaces import AddTwoInts, Fibonacci

    assert msgs.get("example_interfaces/srv/AddTwoInts_Request") is AddTwoInts.Request
    assert msgs.get("example_interfaces/action/Fibonacci_SendGoal_Request") is (
        Fibonacci.SendGoal.Request)
    assert msgs.get("example_interfaces/action/Fibonacci_FeedbackMessage") is (
        Fibonacci.FeedbackMessage)


def test_service_class_structure() -> None:
    from aiorobot.msgs.example_interfaces import AddTwoInts
    from aiorobot.msgs.std_srvs import Empty, SetBool, Trigger

    assert AddTwoInts.__msgtype__ == "example_interfaces/srv/AddTwoInts"
    assert AddTwoInts.Request.__msgtype__ == "example_interfaces/srv/AddTwoInts_Request"
    assert AddTwoInts.Response.__msgtype__ == "example_interfaces/srv/AddTwoInts_Response"
    assert AddTwoInts.Request(a=1, b=2).b == 2
    assert AddTwoInts.Response().sum == 0
    assert issubclass(AddTwoInts, msgs.Service)
    assert Trigger.Response(success=True, message="ok").message == "ok"
    assert SetBool.Request(data=True).data is True
    assert Empty.Request() == Empty.Request()
    event = AddTwoInts.Event()
    assert event.request == [] and event.info.client_gid.shape == (16,)
    with pytest.raises(TypeError, match=r"is a service type, not a message: construct "
                                        r"AddTwoInts.Request\(\)"):
        AddTwoInts()


def test_action_class_structure() -> None:
    from aiorobot.msgs.builtin_interfaces import Time
    from aiorobot.msgs.example_interfaces import Fibonacci
    from aiorobot.msgs.unique_identifier_msgs import UUID

    assert issubclass(Fibonacci, msgs.Action)
    assert Fibonacci.Goal(order=5).order == 5
    assert Fibonacci.Result().sequence.dtype == np.int32
    assert Fibonacci.Feedback.__msgtype__ == "example_interfaces/action/Fibonacci_Feedback"
    send = Fibonacci.SendGoal
    assert issubclass(send, msgs.Service)
    assert send.__msgtype__ == "example_interfaces/action/Fibonacci_SendGoal"
    assert send.Request.__msgtype__ == "example_interfaces/action/Fibonacci_SendGoal_Request"
    request = send.Request(goal=Fibonacci.Goal(order=3))
    assert isinstance(request.goal_id, UUID) and request.goal.order == 3
    response = send.Response(accepted=True)
    assert isinstance(response.stamp, Time)
    result_request = Fibonacci.GetResult.Request()
    assert isinstance(result_request.goal_id, UUID)
    result = Fibonacci.GetResult.Response(status=4, result=Fibonacci.Result(sequence=[0, 1]))
    assert result.result.sequence.tolist() == [0, 1]
    assert Fibonacci.GetResult.Response.__msgtype__ == (
        "example_interfaces/action/Fibonacci_GetResult_Response")
    fb = Fibonacci.FeedbackMessage()
    assert isinstance(fb.goal_id, UUID) and isinstance(fb.feedback, Fibonacci.Feedback)
    assert fb.__msgtype__ == "example_interfaces/action/Fibonacci_FeedbackMessage"
    with pytest.raises(TypeError, match=r"is an action type"):
        Fibonacci()


@pytest.mark.parametrize("name", [
    "std_srvs/srv/Empty", "std_srvs/srv/Trigger", "std_srvs/srv/SetBool",
    "example_interfaces/srv/AddTwoInts", "example_interfaces/srv/Trigger",
    "example_interfaces/srv/SetBool", "lifecycle_msgs/srv/ChangeState",
    "lifecycle_msgs/srv/GetState", "lifecycle_msgs/srv/GetAvailableStates",
    "lifecycle_msgs/srv/GetAvailableTransitions", "action_msgs/srv/CancelGoal",
    "rcl_interfaces/srv/GetParameters", "rcl_interfaces/srv/SetParameters",
    "rcl_interfaces/srv/ListParameters", "rcl_interfaces/srv/DescribeParameters",
    "rcl_interfaces/srv/GetParameterTypes", "rcl_interfaces/srv/SetParametersAtomically",
])
def test_shipped_services_exist(name: str) -> None:
    srv = msgs.get(name)
    assert srv.__msgtype__ == name
    assert msgs.deserialize(msgs.serialize(srv.Request()), srv.Request) == srv.Request()
    assert msgs.deserialize(msgs.serialize(srv.Response()), srv.Response) == srv.Response()


def test_cancel_goal_response_constants() -> None:
    from aiorobot.msgs.action_msgs import CancelGoal

    assert CancelGoal.Response.ERROR_NONE == 0
    assert CancelGoal.Response.ERROR_GOAL_TERMINATED == 3


def test_register_msg_makes_the_type_usable() -> None:
    msgs.register_msg("float64 x\nfloat64 y", "test_registry_msgs/msg/Point")
    cls = msgs.register_msg(
        "# a test message\n"
        "int32 LIMIT=10\n"
        "string STATE_NAME=running # not a comment in string constants\n"
        "std_msgs/Header header\n"
        "float64[3] gains\n"
        "Point[] points  # resolves within the package\n"
        "string<=8 label\n"
        "uint8[<=4] flags\n"
        "float32 scale 2.5\n",
        "test_registry_msgs/msg/Sample",
    )
    assert msgs.get("test_registry_msgs/msg/Sample") is cls
    assert msgs.get("test_registry_msgs/Sample") is cls
    assert cls.LIMIT == 10 and cls.STATE_NAME == "running # not a comment in string constants"
    sample = cls(points=[msgs.get("test_registry_msgs/msg/Point")(x=1.0)], label="abc")
    assert sample.scale == 2.5 and sample.gains.shape == (3,)
    assert msgs.deserialize(msgs.serialize(sample), "test_registry_msgs/msg/Sample") == sample
    assert msgs.type_hash(cls).startswith("RIHS01_")
    assert "MSG: test_registry_msgs/Point" in msgs.message_definition(cls)
    with pytest.raises(ValueError, match=r"Sample\.label is bounded to 8 characters, got 9"):
        cls(label="123456789")
    too_long = cls()
    too_long.label = "123456789"  # assignment is not checked: the serializer is
    with pytest.raises(msgs.SerializationError, match=r"field 'label' is bounded to 8 characters"):
        msgs.serialize(too_long)


def test_registering_an_identical_definition_is_a_no_op() -> None:
    first = msgs.register_msg("int32 a\nint32 b", "test_registry_msgs/msg/Pair")
    again = msgs.register_msg("int32 a   # comments do not matter\nint32 b\n", "test_registry_msgs/msg/Pair")
    assert first is again


def test_registering_a_conflicting_definition_names_both() -> None:
    msgs.register_msg("int32 a", "test_registry_msgs/msg/Conflict")
    with pytest.raises(ValueError, match=r"(?s)conflicting definition for "
                                         r"'test_registry_msgs/msg/Conflict'.*int32 a.*float64 a"):
        msgs.register_msg("float64 a", "test_registry_msgs/msg/Conflict")
    with pytest.raises(ValueError, match=r"conflicting definition for 'std_msgs/msg/String'"):
        msgs.register_msg("int32 data", "std_msgs/msg/String")
    assert msgs.register_msg("string data", "std_msgs/msg/String") is msgs.get("std_msgs/String")


def test_register_srv_and_action() -> None:
    srv = msgs.register_srv("string name\n---\nbool ok\nstring[] notes", "test_registry_msgs/srv/Check")
    assert srv.Request.__msgtype__ == "test_registry_msgs/srv/Check_Request"
    response = srv.Response(ok=True, notes=["a"])
    assert msgs.deserialize(msgs.serialize(response), srv.Response) == response
    act = msgs.register_action("float64 distance\n---\nbool arrived\n---\nfloat64 remaining",
                               "test_registry_msgs/action/Drive")
    assert act.Goal(distance=2.0).distance == 2.0
    assert act.SendGoal.Request().goal == act.Goal()
    assert act.GetResult.Response().result == act.Result()
    assert act.FeedbackMessage.__msgtype__ == "test_registry_msgs/action/Drive_FeedbackMessage"
    assert msgs.get("test_registry_msgs/action/Drive") is act
    assert msgs.type_hash(act).startswith("RIHS01_")


def test_register_file_infers_the_name_from_the_path(tmp_path: Path) -> None:
    folder = tmp_path / "test_file_msgs" / "msg"
    folder.mkdir(parents=True)
    (folder / "Reading.msg").write_text("float64 value\nstring unit\n")
    cls = msgs.register_file(folder / "Reading.msg")
    assert cls.__msgtype__ == "test_file_msgs/msg/Reading"
    srv_dir = tmp_path / "test_file_msgs" / "srv"
    srv_dir.mkdir()
    (srv_dir / "Calibrate.srv").write_text("Reading reference\n---\nbool ok\n")
    srv = msgs.register_file(str(srv_dir / "Calibrate.srv"))
    assert srv.Request().reference == cls()
    with pytest.raises(ValueError, match=r"cannot infer the type name from .*Reading.txt"):
        msgs.register_file(folder / "Reading.txt")


@pytest.mark.parametrize(("text", "error"), [
    ("int32", r"expected 'type name'"),
    ("float64 Bad", r"invalid field name 'Bad'"),
    ("int32 class", r"invalid field name 'class'"),
    ("int32 a\nint32 a", r"duplicate field name 'a'"),
    ("uint8 X=300", r"value 300 is out of range for uint8"),
    ("strange!type x", r"invalid field type 'strange!type'"),
    ("float64[0] x", r"fixed arrays need a length > 0"),
])
def test_bad_definitions_are_rejected_with_the_line(text: str, error: str) -> None:
    with pytest.raises(ValueError, match=r"test_bad_msgs/msg/Bad line \d+: " + error):
        msgs.register_msg(text, "test_bad_msgs/msg/Bad")


def test_bad_names_are_rejected() -> None:
    with pytest.raises(ValueError, match=r"expected a type name like 'my_pkg/msg/Name', "
                                         r"got 'Bad'"):
        msgs.register_msg("int32 a", "Bad")
    with pytest.raises(ValueError, match=r"expected 2 sections separated by '---'"):
        msgs.register_srv("int32 a", "test_bad_msgs/srv/NoSeparator")


def test_registering_a_type_with_an_unknown_nested_type_registers_nothing() -> None:
    with pytest.raises(LookupError, match=r"^cannot register 'test_missing_msgs/msg/Holder': "
                                          r"unknown interface type 'test_missing_msgs/msg/Unknown'"
                                          r".*; register the types it uses first$"):
        msgs.register_msg("test_missing_msgs/Unknown thing", "test_missing_msgs/msg/Holder")
    with pytest.raises(LookupError):
        msgs.get("test_missing_msgs/msg/Holder")
    msgs.register_msg("int8 level", "test_missing_msgs/msg/Unknown")
    holder = msgs.register_msg("test_missing_msgs/Unknown thing", "test_missing_msgs/msg/Holder")
    assert holder().thing.level == 0


def test_package_modules_import_and_list_their_types() -> None:
    geometry = importlib.import_module("aiorobot.msgs.geometry_msgs")
    assert "Twist" in geometry.__all__ and "Twist" in dir(geometry)
    assert geometry.Twist is msgs.get("geometry_msgs/msg/Twist")
    std_srvs = importlib.import_module("aiorobot.msgs.std_srvs")
    assert set(std_srvs.__all__) >= {"Empty", "SetBool", "Trigger"}
    with pytest.raises(AttributeError, match=r"has no interface type 'Twst'; did you mean 'Twist'"):
        geometry.Twst  # noqa: B018
    with pytest.raises(ImportError):
        exec("from aiorobot.msgs.geometry_msgs import Nothing", {})  # noqa: S102


def test_every_package_module_lists_buildable_types() -> None:
    from aiorobot.msgs._stubgen import packages

    for pkg, names in packages().items():
        module = importlib.import_module(f"aiorobot.msgs.{pkg}")
        assert module.__all__ == names
        for name in names:
            assert getattr(module, name).__msgtype__.split("/")[2] == name


def test_string_constants_and_defaults_keep_unicode_and_decode_escapes() -> None:
    cls = msgs.register_msg('string GREETING="héllo\\tworld"\nstring name "Zoë"\nbool on true',
                            "test_registry_msgs/msg/Greeting")
    assert cls.GREETING == "héllo\tworld"
    assert cls().name == "Zoë" and cls().on is True


def test_shipped_definitions_keep_upstream_defaults() -> None:
    from aiorobot.msgs.type_description_interfaces import GetTypeDescription

    assert GetTypeDescription.Request().include_type_sources is True
