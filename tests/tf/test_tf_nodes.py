"""Broadcasters, listener and robot state publisher on a local runtime."""

from __future__ import annotations

import asyncio
import concurrent.futures
import logging
import math
from pathlib import Path

import pytest
from _tf_helpers import q_of, sec_of, tf, xyz_of, yaw_q

from aiorobot import DurabilityPolicy, Node, Parameter, ReliabilityPolicy, Runtime, Time
from aiorobot.msgs.sensor_msgs import JointState
from aiorobot.msgs.tf2_msgs import TFMessage
from aiorobot.tf import (
    Buffer,
    RobotStatePublisher,
    StaticTransformBroadcaster,
    TransformBroadcaster,
    TransformListener,
    URDFError,
)

GENEROUS_SEC = 30.0
ARM = Path(__file__).resolve().parents[2] / "examples" / "urdf" / "two_dof_arm.urdf"


class Listening(Node):
    def __init__(self, name: str = "listening", **kw):
        super().__init__(name, **kw)
        self.buffer = Buffer()
        self.listener = TransformListener(self.buffer, self)


def joint_state(sec: float, **positions: float) -> JointState:
    msg = JointState(name=list(positions), position=list(positions.values()))
    msg.header.stamp = Time(seconds=sec).to_msg()
    return msg


@pytest.fixture
async def rt():
    async with Runtime(handle_signals=False) as runtime:
        yield runtime


# ----------------------------------------------------------------------------- broadcasters + listener


async def test_broadcast_transforms_reach_a_listening_buffer(rt):
    talker = rt.add_node(Node("talker"))
    sink = rt.add_node(Listening())
    broadcaster = TransformBroadcaster(talker)
    broadcaster.send_transform(tf("odom", "base_link", 5, (1, 2, 0), yaw_q(0.5)))
    broadcaster.send_transform([tf("odom", "base_link", 6, (2, 2, 0)), tf("map", "odom", 6, (0, 1, 0))])
    await sink.buffer.wait_for_transform("map", "base_link", Time(seconds=6), GENEROUS_SEC)
    assert xyz_of(sink.buffer.lookup_transform("map", "base_link", Time(seconds=6))) == pytest.approx((2, 3, 0))
    assert q_of(sink.buffer.lookup_transform("odom", "base_link", Time(seconds=5))) == pytest.approx(yaw_q(0.5))


async def test_late_joiners_get_every_static_transform_ever_sent(rt):
    talker = rt.add_node(Node("mounts"))
    statics = StaticTransformBroadcaster(talker)
    statics.send_transform(tf("base_link", "lidar_link", 0, (0.2, 0, 0.3)))
    statics.send_transform(tf("base_link", "imu_link", 0, (0, 0, 0.1)))
    statics.send_transform(tf("base_link", "lidar_link", 0, (0.25, 0, 0.3)))  # replaces by child frame
    assert len(statics.transforms) == 2
    late = rt.add_node(Listening("late"))
    await late.buffer.wait_for_transform("lidar_link", "imu_link", Time(), GENEROUS_SEC)
    assert xyz_of(late.buffer.lookup_transform("base_link", "lidar_link", Time(seconds=123))) == pytest.approx((0.25, 0, 0.3))
    assert sec_of(late.buffer.lookup_transform("base_link", "imu_link", Time(seconds=123))) == 123.0


async def test_listener_uses_tf2_qos(rt):
    sink = rt.add_node(Listening())
    by_topic = {s.topic_name: s.qos for s in sink.subscriptions}
    assert by_topic["/tf"].reliability is ReliabilityPolicy.RELIABLE
    assert by_topic["/tf"].durability is DurabilityPolicy.VOLATILE
    assert by_topic["/tf"].depth == 100
    assert by_topic["/tf_static"].durability is DurabilityPolicy.TRANSIENT_LOCAL
    assert by_topic["/tf_static"].depth == 1


async def test_listener_logs_and_drops_bad_samples_and_keeps_the_rest(rt, caplog):
    talker = rt.add_node(Node("noisy"))
    sink = rt.add_node(Listening())
    pub = talker.create_publisher(TFMessage, "/tf", 100)
    bad = tf("odom", "base_link", 1, (math.nan, 0, 0))
    good = tf("map", "odom", 1, (1, 0, 0))
    with caplog.at_level(logging.WARNING):
        pub.publish(TFMessage(transforms=[bad, good]))
        await sink.buffer.wait_for_transform("map", "odom", Time(seconds=1), GENEROUS_SEC)
    assert sink.listener.dropped == 1
    assert sink.listener.received == 2
    assert "dropped a transform received on /tf: " in caplog.text
    assert "TF_NAN_INPUT" in caplog.text
    assert not sink.buffer.can_transform("odom", "base_link", Time(seconds=1))


async def test_buffer_filled_on_the_main_loop_is_read_from_the_priority_loop(rt):
    sink = rt.add_node(Listening())
    talker = rt.add_node(Node("talker"))
    result: concurrent.futures.Future[float] = concurrent.futures.Future()

    class Controller(Node):
        def __init__(self):
            super().__init__("controller")

        async def on_start(self) -> None:
            # waits on the priority loop; woken by the listener's insert on the main loop
            out = await sink.buffer.lookup_transform_async("odom", "base_link", Time(seconds=2), GENEROUS_SEC)
            result.set_result(xyz_of(out)[0])

    rt.add_node(Controller(), executor="priority")
    TransformBroadcaster(talker).send_transform(tf("odom", "base_link", 2, (7, 0, 0)))
    assert await asyncio.wait_for(asyncio.wrap_future(result), GENEROUS_SEC) == 7.0


# ----------------------------------------------------------------------------- robot state publisher


def rsp(**params) -> RobotStatePublisher:
    return RobotStatePublisher(parameter_overrides={"robot_description_file": str(ARM), **params})


async def test_fixed_joints_are_published_on_tf_static(rt):
    rt.add_node(rsp())
    sink = rt.add_node(Listening())
    await sink.buffer.wait_for_transform("base_link", "lidar_link", Time(), GENEROUS_SEC)
    await sink.buffer.wait_for_transform("forearm", "tool0", Time(), GENEROUS_SEC)
    assert xyz_of(sink.buffer.lookup_transform("base_link", "arm_base", Time())) == pytest.approx((0.1, 0, 0.25))
    lidar = sink.buffer.lookup_transform("base_link", "lidar_link", Time())
    assert xyz_of(lidar) == pytest.approx((0.2, 0, 0.35))
    assert q_of(lidar) == pytest.approx((0, 0, 1, 0), abs=1e-6)
    assert not sink.buffer.can_transform("arm_base", "upper_arm", Time())  # moving: not static


async def test_joint_states_move_the_arm_on_tf(rt):
    node = rt.add_node(rsp())
    sink = rt.add_node(Listening())
    driver = rt.add_node(Node("driver"))
    pub = driver.create_publisher(JointState, "/joint_states", 10)
    pub.publish(joint_state(4.0, shoulder_joint=math.pi / 2, elbow_joint=-math.pi / 2))
    await sink.buffer.wait_for_transform("base_link", "tool0", Time(seconds=4), GENEROUS_SEC)
    tip = sink.buffer.lookup_transform("base_link", "tool0", Time(seconds=4))
    # shoulder turns the arm to +y; the elbow (about y) lifts the 0.25 m forearm straight up
    assert xyz_of(tip) == pytest.approx((0.1, 0.3, 0.25 + 0.05 + 0.25))
    assert sec_of(tip) == 4.0
    assert node.model.name == "two_dof_arm"


async def test_unknown_joints_warn_and_the_rest_still_publish(rt, caplog):
    rt.add_node(rsp())
    sink = rt.add_node(Listening())
    driver = rt.add_node(Node("driver"))
    pub = driver.create_publisher(JointState, "/joint_states", 10)
    with caplog.at_level(logging.WARNING):
        pub.publish(joint_state(1.0, wrist_joint=0.3, shoulder_joint=0.0))
        await sink.buffer.wait_for_transform("arm_base", "upper_arm", Time(seconds=1), GENEROUS_SEC)
    assert 'joint state with name "wrist_joint" was received but not found in the URDF' in caplog.text


async def test_invalid_joint_states_are_ignored_with_an_error(rt, caplog):
    node = rt.add_node(rsp())
    driver = rt.add_node(Node("driver"))
    sink = rt.add_node(Listening())
    pub = driver.create_publisher(JointState, "/joint_states", 10)
    bad = JointState(name=["shoulder_joint", "elbow_joint"], position=[0.1])
    with caplog.at_level(logging.WARNING):
        pub.publish(bad)
        pub.publish(joint_state(2.0, shoulder_joint=0.1, elbow_joint=0.0))
        await sink.buffer.wait_for_transform("arm_base", "forearm", Time(seconds=2), GENEROUS_SEC)
    assert "ignored an invalid JointState: 2 names but 1 positions" in caplog.text
    assert node.model is not None


async def test_publish_frequency_limits_the_rate_per_joint(rt):
    rt.add_node(rsp(publish_frequency=10.0))
    sink = rt.add_node(Listening())
    driver = rt.add_node(Node("driver"))
    pub = driver.create_publisher(JointState, "/joint_states", 10)
    for sec in (1.0, 1.05, 1.2):  # 1.05 is within 0.1 s of 1.0: skipped
        pub.publish(joint_state(sec, shoulder_joint=sec))
    await sink.buffer.wait_for_transform("arm_base", "upper_arm", Time(seconds=1.2), GENEROUS_SEC)
    yaml = sink.buffer.all_frames_as_yaml()
    assert "upper_arm: \n  parent: 'arm_base'\n  broadcaster: 'default_authority'\n  rate: 10.000\n" in yaml


def test_malformed_or_missing_descriptions_fail_at_construction():
    with pytest.raises(URDFError, match=r"^/robot_state_publisher: no robot description; set the robot_description parameter"):
        RobotStatePublisher()
    with pytest.raises(URDFError, match=r"parameter robot_description: not well-formed XML at line 1"):
        RobotStatePublisher(parameter_overrides={"robot_description": "<robot><link name='a'>"})


async def test_setting_a_malformed_description_is_rejected_and_a_valid_one_applied(rt):
    node = rt.add_node(rsp())
    sink = rt.add_node(Listening())
    [bad] = node.set_parameters([Parameter("robot_description", "<robot><joint/></robot>")])
    assert not bad.successful
    assert "no <link> elements" in bad.reason
    assert node.model.name == "two_dof_arm"
    new = (
        '<robot name="box"><link name="base_link"/><link name="camera"/>'
        '<joint name="cam" type="fixed"><parent link="base_link"/><child link="camera"/>'
        '<origin xyz="0 0 1"/></joint></robot>'
    )
    [ok] = node.set_parameters([Parameter("robot_description", new)])
    assert ok.successful, ok.reason
    await sink.buffer.wait_for_transform("base_link", "camera", Time(), GENEROUS_SEC)
    assert xyz_of(sink.buffer.lookup_transform("base_link", "camera", Time())) == pytest.approx((0, 0, 1))


async def test_frame_prefix_is_prepended(rt):
    rt.add_node(rsp(frame_prefix="arm1/"))
    sink = rt.add_node(Listening())
    await sink.buffer.wait_for_transform("arm1/base_link", "arm1/lidar_link", Time(), GENEROUS_SEC)


async def test_mimic_joints_follow_their_leader(rt):
    text = (
        '<robot name="gripper"><link name="palm"/><link name="left"/><link name="right"/>'
        '<joint name="left_joint" type="prismatic"><parent link="palm"/><child link="left"/>'
        '<axis xyz="0 1 0"/><limit lower="0" upper="0.05" effort="1" velocity="1"/></joint>'
        '<joint name="right_joint" type="prismatic"><parent link="palm"/><child link="right"/>'
        '<axis xyz="0 1 0"/><limit lower="-0.05" upper="0" effort="1" velocity="1"/>'
        '<mimic joint="left_joint" multiplier="-1"/></joint></robot>'
    )
    rt.add_node(RobotStatePublisher(parameter_overrides={"robot_description": text}))
    sink = rt.add_node(Listening())
    driver = rt.add_node(Node("driver"))
    driver.create_publisher(JointState, "/joint_states", 10).publish(joint_state(3.0, left_joint=0.02))
    await sink.buffer.wait_for_transform("left", "right", Time(seconds=3), GENEROUS_SEC)
    assert xyz_of(sink.buffer.lookup_transform("left", "right", Time(seconds=3))) == pytest.approx((0, -0.04, 0))
