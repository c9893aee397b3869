"""Property tests: any valid message round-trips and encodes exactly as rosbags does."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import aiorobot.msgs as msgs
from aiorobot.msgs._spec import ARRAY, PRIMITIVES, SCALAR, FieldType

from ._helpers import rosbags_store, to_rosbags

_INTS = {
    "byte": (0, 127), "char": (0, 255), "int8": (-128, 127), "uint8": (0, 255),
    "int16": (-(2**15), 2**15 - 1), "uint16": (0, 2**16 - 1),
    "int32": (-(2**31), 2**31 - 1), "uint32": (0, 2**32 - 1),
    "int64": (-(2**63), 2**63 - 1), "uint64": (0, 2**64 - 1),
}
_TEXT = st.text(st.characters(exclude_categories=("Cs",), exclude_characters="\x00"), max_size=12)


def _scalar(t: FieldType) -> st.SearchStrategy[Any]:
    if t.base == "bool":
        return st.booleans()
    if t.base == "float64":
        return st.floats(allow_nan=False)
    if t.base == "float32":
        return st.floats(width=32, allow_nan=False)
    if t.is_string:
        if t.string_bound:
            return st.text(st.characters(max_codepoint=127, exclude_characters="\x00"),
                           max_size=t.string_bound)
        return _TEXT
    lo, hi = _INTS[t.base]
    return st.integers(lo, hi)


def _value(t: FieldType) -> st.SearchStrategy[Any]:
    if t.kind == SCALAR:
        return message(msgs.get(t.base)) if t.is_message else _scalar(t)
    size = {"min_size": t.count, "max_size": t.count} if t.kind == ARRAY else {
        "max_size": t.count or 4}
    items = st.lists(_value(t.element), **size)
    if t.is_primitive:
        dtype = np.dtype(PRIMITIVES[t.base][2])
        return items.map(lambda xs: np.array(xs, dtype=dtype))
    return items


def message(cls: type) -> st.SearchStrategy[Any]:
    spec = cls._spec  # type: ignore[attr-defined]
    return st.builds(cls, **{f.name: _value(f.type) for f in spec.fields})


TYPES = [
    "geometry_msgs/msg/Twist", "sensor_msgs/msg/JointState", "sensor_msgs/msg/Image",
    "sensor_msgs/msg/PointCloud2", "sensor_msgs/msg/CameraInfo", "sensor_msgs/msg/NavSatFix",
    "visualization_msgs/msg/Marker", "rcl_interfaces/msg/ParameterValue",
    "rcl_interfaces/msg/ParameterDescriptor", "diagnostic_msgs/msg/DiagnosticArray",
    "shape_msgs/msg/SolidPrimitive", "rmw_dds_common/msg/NodeEntitiesInfo",
    "tf2_msgs/msg/TFMessage", "nav_msgs/msg/OccupancyGrid", "std_msgs/msg/ByteMultiArray",
]


@pytest.mark.parametrize("name", TYPES)
def test_round_trip_and_byte_identity(name: str) -> None:
    @settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
    @given(message(msgs.get(name)))
    def check(msg: Any) -> None:
        data = msgs.serialize(msg)
        assert msgs.deserialize(data, name) == msg
        expected = rosbags_store().serialize_cdr(to_rosbags(msg), name, little_endian=True)
        assert data == bytes(expected)

    check()


@pytest.mark.parametrize("name", ["example_interfaces/msg/WString",
                                  "example_interfaces/action/Fibonacci_SendGoal_Request",
                                  "example_interfaces/action/Fibonacci_GetResult_Response",
                                  "rcl_interfaces/srv/SetParameters_Request",
                                  "action_msgs/srv/CancelGoal_Response"])
def test_round_trip_of_shipped_types(name: str) -> None:
    @settings(max_examples=40, deadline=None)
    @given(message(msgs.get(name)))
    def check(msg: Any) -> None:
        assert msgs.deserialize(msgs.serialize(msg), name) == msg

    check()


@settings(max_examples=200, deadline=None)
@given(st.binary(max_size=120))
def test_arbitrary_bytes_decode_or_raise_deserialization_error(payload: bytes) -> None:
    for name in ("sensor_msgs/msg/JointState", "visualization_msgs/msg/Marker",
                 "rcl_interfaces/msg/ParameterEvent"):
        try:
            msgs.deserialize(b"\x00\x01\x00\x00" + payload, name)
        except msgs.DeserializationError:
            pass
