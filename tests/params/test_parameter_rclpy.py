"""rclpy's test_parameter.py cases, restated for aiorobot.Parameter (upstream: ros2/rclpy 8.0.0)."""

from __future__ import annotations

from array import array

import pytest

from aiorobot import Parameter
from aiorobot.parameters import get_parameter_value, parameter_value_to_python
from aiorobot.msgs.rcl_interfaces import Parameter as ParameterMsg
from aiorobot.msgs.rcl_interfaces import ParameterType, ParameterValue


@pytest.mark.parametrize(
    ("type_", "value"),
    [
        (Parameter.Type.BOOL, True),
        (Parameter.Type.BYTE_ARRAY, [b"p", b"v", b"a", b"l", b"u", b"e"]),
        (Parameter.Type.DOUBLE, 2.41),
        (Parameter.Type.INTEGER, 42),
        (Parameter.Type.STRING, "pvalue"),
        (Parameter.Type.BOOL_ARRAY, [True, False, True]),
        (Parameter.Type.DOUBLE_ARRAY, [2.41, 6.28]),
        (Parameter.Type.INTEGER_ARRAY, [1, 2, 3]),
        (Parameter.Type.STRING_ARRAY, ["hello", "world"]),
    ],
)
def test_create_parameters(type_, value):
    # rclpy test_parameter.py::test_create_boolean_parameter ... ::test_create_string_array_parameter
    p = Parameter("myparam", type_, value)
    assert p.name == "myparam" and p.value == value and p.type_ == type_
    p = Parameter("myparam", value=value)
    assert p.type_ == type_ and p.value == value


def test_create_not_set_parameter():
    # rclpy test_parameter.py::test_create_not_set_parameter
    assert Parameter("myparam", Parameter.Type.NOT_SET).value is None
    for p in (Parameter("myparam"), Parameter("myparam", value=None)):
        assert p.value is None and p.type_ == Parameter.Type.NOT_SET


def test_value_and_type_must_agree():
    # rclpy test_parameter.py::test_value_and_type_must_agree
    with pytest.raises(ValueError):
        Parameter("myparam", Parameter.Type.NOT_SET, 42)
    with pytest.raises(ValueError):
        Parameter("myparam", Parameter.Type.BOOL_ARRAY, 42)


def test_error_on_illegal_value_type():
    # rclpy test_parameter.py::test_error_on_illegal_value_type
    with pytest.raises(TypeError):
        Parameter("illegaltype", "mytype", "myvalue")
    with pytest.raises(TypeError):
        Parameter("illegaltype", value={"invalid": "type"})


def test_aiorobot_two_argument_form_is_name_and_value():
    p = Parameter("gain", 0.5)
    assert p.type_ is Parameter.Type.DOUBLE and p.value == 0.5


def test_integer_tuple_and_arrays():
    # rclpy test_parameter.py::test_integer_tuple_array, ::test_integer_array, ::test_double_array
    assert Parameter.Type.from_parameter_value([1, 2, 3]) == Parameter.Type.INTEGER_ARRAY
    assert Parameter.Type.check(Parameter.Type.INTEGER_ARRAY, [1, 2, 3])
    assert Parameter.Type.from_parameter_value((1, 2, 3)) == Parameter.Type.INTEGER_ARRAY
    assert Parameter.Type.check(Parameter.Type.INTEGER_ARRAY, (1, 2, 3))
    assert Parameter.Type.from_parameter_value(array("i", [1, 2, 3])) == Parameter.Type.INTEGER_ARRAY
    assert Parameter.Type.from_parameter_value(array("d", [1.0, 2.0])) == Parameter.Type.DOUBLE_ARRAY
    p = Parameter.from_parameter_msg(
        ParameterMsg(name="int_array", value=ParameterValue(type=7, integer_array_value=[1, 2, 3]))
    )
    assert p.value == [1, 2, 3] and p.type_ is Parameter.Type.INTEGER_ARRAY
    p = Parameter.from_parameter_msg(
        ParameterMsg(name="double_array", value=ParameterValue(type=8, double_array_value=[1.0, 2.0, 3.0]))
    )
    assert p.value == [1.0, 2.0, 3.0]


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("True", ParameterValue(type=ParameterType.PARAMETER_BOOL, bool_value=True)),
        ("42", ParameterValue(type=ParameterType.PARAMETER_INTEGER, integer_value=42)),
        ("3.5", ParameterValue(type=ParameterType.PARAMETER_DOUBLE, double_value=3.5)),
        ("foo", ParameterValue(type=ParameterType.PARAMETER_STRING, string_value="foo")),
        (" ", ParameterValue(type=ParameterType.PARAMETER_STRING, string_value=" ")),
        ("", ParameterValue(type=ParameterType.PARAMETER_STRING, string_value="")),
        ("[True, False]", ParameterValue(type=ParameterType.PARAMETER_BOOL_ARRAY, bool_array_value=[True, False])),
        ("[1, 2, 3]", ParameterValue(type=ParameterType.PARAMETER_INTEGER_ARRAY, integer_array_value=[1, 2, 3])),
        ("[1.0, 2.0]", ParameterValue(type=ParameterType.PARAMETER_DOUBLE_ARRAY, double_array_value=[1.0, 2.0])),
        ("['foo', 'bar']", ParameterValue(type=ParameterType.PARAMETER_STRING_ARRAY, string_array_value=["foo", "bar"])),
        ("[1, 2.5]", ParameterValue(type=ParameterType.PARAMETER_STRING, string_value="[1, 2.5]")),
    ],
)
def test_get_parameter_value(text, expected):
    # rclpy test_parameter.py::test_get_parameter_value
    assert get_parameter_value(text) == expected


def test_parameter_value_to_python():
    # rclpy test_parameter.py::test_parameter_value_to_python
    cases = [
        (ParameterValue(type=ParameterType.PARAMETER_NOT_SET), None),
        (ParameterValue(type=ParameterType.PARAMETER_INTEGER, integer_value=42), 42),
        (ParameterValue(type=ParameterType.PARAMETER_DOUBLE, double_value=3.5), 3.5),
        (ParameterValue(type=ParameterType.PARAMETER_STRING, string_value="foo"), "foo"),
        (ParameterValue(type=ParameterType.PARAMETER_BYTE_ARRAY, byte_array_value=[74, 80]), [b"J", b"P"]),
        (ParameterValue(type=ParameterType.PARAMETER_INTEGER_ARRAY, integer_array_value=[1, 2, 3]), [1, 2, 3]),
        (ParameterValue(type=ParameterType.PARAMETER_DOUBLE_ARRAY, double_array_value=[1.0, 2.0]), [1.0, 2.0]),
        (ParameterValue(type=ParameterType.PARAMETER_STRING_ARRAY, string_array_value=["foo", "bar"]), ["foo", "bar"]),
    ]
    for msg, expected in cases:
        assert parameter_value_to_python(msg) == expected
    with pytest.raises(RuntimeError):
        parameter_value_to_python(ParameterValue(type=42))


def test_get_parameter_value_round_trips_through_messages():
    # rclpy Parameter.get_parameter_value / to_parameter_msg / from_parameter_msg
    for p in (
        Parameter("b", value=[b"p", b"v"]),
        Parameter("i", value=7),
        Parameter("s", value=["a"]),
        Parameter("n"),
    ):
        msg = p.to_parameter_msg()
        assert msg.value.type == int(p.type_)
        assert Parameter.from_parameter_msg(msg) == p
    assert Parameter("b", value=[b"p", b"v"]).get_parameter_value().byte_array_value.tolist() == [112, 118]
