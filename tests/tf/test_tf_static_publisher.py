"""``aiorobot.tf:StaticTransformPublisher``, tf2_ros's static_transform_publisher node.

Upstream: geometry2 tf2_ros/src/static_transform_broadcaster_node.cpp (parameter names, defaults,
read-only descriptors, frame_id == child_frame_id refused); the program's --roll/--pitch/--yaw.
"""

from __future__ import annotations

import math
import textwrap

import pytest
from _tf_helpers import q_of, xyz_of, yaw_q

from aiorobot import Node, Runtime, Time
from aiorobot.tf import Buffer, StaticTransformPublisher, TransformListener

GENEROUS_SEC = 30.0


class Listening(Node):
    def __init__(self, name: str = "listening", **kw):
        super().__init__(name, **kw)
        self.buffer = Buffer()
        self.listener = TransformListener(self.buffer, self)


@pytest.fixture
async def rt():
    async with Runtime(handle_signals=False) as runtime:
        yield runtime


async def test_publishes_the_parameters_transform_to_a_late_listener(rt):
    rt.add_node(StaticTransformPublisher(parameter_overrides={
        "frame_id": "map", "child_frame_id": "odom", "translation.x": 1.0, "translation.y": -2.0,
        "translation.z": 0.5, "rotation.z": math.sin(0.25), "rotation.w": math.cos(0.25)}))
    late = rt.add_node(Listening())
    await late.buffer.wait_for_transform("map", "odom", Time(), GENEROUS_SEC)
    t = late.buffer.lookup_transform("map", "odom", Time())
    assert xyz_of(t) == pytest.approx((1.0, -2.0, 0.5))
    assert q_of(t) == pytest.approx(yaw_q(0.5))


async def test_roll_pitch_yaw_give_the_rotation(rt):
    node = rt.add_node(StaticTransformPublisher(parameter_overrides={
        "frame_id": "base_link", "child_frame_id": "laser", "yaw": 0.5}))
    assert q_of(node.transform) == pytest.approx(yaw_q(0.5))


def test_defaults_and_read_only_parameters_as_tf2_ros():
    node = StaticTransformPublisher()
    assert node.get_parameter("frame_id").value == "/frame"
    assert node.get_parameter("child_frame_id").value == "/child"
    assert node.get_parameter("rotation.w").value == 1.0
    assert node.describe_parameter("translation.x").read_only
    assert xyz_of(node.transform) == (0.0, 0.0, 0.0)


@pytest.mark.parametrize("overrides, words", [
    ({"frame_id": "odom", "child_frame_id": "odom"}, "to itself"),
    ({"rotation.w": 2.0}, "unit quaternion"),
    ({"rotation.z": 1.0, "yaw": 0.3}, "not both"),
    ({"translation.x": math.nan}, "translation.x must be a finite number"),
])
def test_bad_parameters_are_one_clear_error(overrides, words):
    with pytest.raises(ValueError, match=words):
        StaticTransformPublisher(parameter_overrides=overrides)


def test_builds_from_a_config_with_nested_parameter_tables(tmp_path):
    from aiorobot.launch import build_nodes, load_config

    path = tmp_path / "graph.toml"
    path.write_text(textwrap.dedent("""
        [[nodes]]
        name = "map_to_odom"
        use = "aiorobot.tf:StaticTransformPublisher"
        parameters = { frame_id = "map", child_frame_id = "odom", translation = { x = 1.5 }, yaw = 0.5 }
    """))
    [(node, _executor)] = build_nodes(load_config(path))
    assert node.get_name() == "map_to_odom"
    assert xyz_of(node.transform) == pytest.approx((1.5, 0.0, 0.0))
    assert q_of(node.transform) == pytest.approx(yaw_q(0.5))
    