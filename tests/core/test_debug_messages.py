"""Runtime(debug_messages=True) reports breaches of the zero-copy contract."""

import logging

import numpy as np
import pytest

from aiorobot import Node, Runtime
from aiorobot.msgs.sensor_msgs import Image
from aiorobot.msgs.std_msgs import Int32
from aiorobot.testing import settle


def _errors(caplog):
    return [r.getMessage() for r in caplog.records if r.levelno == logging.ERROR]


async def test_writing_through_a_view_of_a_shared_array_is_reported(caplog):
    # publish makes the message's large array read-only, but not the array it is a view of
    frame = np.zeros((64, 64, 3), np.uint8)
    async with Runtime(debug_messages=True, handle_signals=False) as rt:
        node = rt.add_node(Node("camera"))
        pub = node.create_publisher(Image, "/camera", 10)
        node.create_subscription(Image, "/camera", lambda m: None, 10)
        for i in range(2):
            frame[:] = i  # a driver refilling its buffer in place
            pub.publish(Image(height=64, width=64, encoding="rgb8", step=192, data=frame.reshape(-1)))
        await settle(rt)
    [error] = _errors(caplog)
    assert "debug_messages: a message published on /camera was changed after publish" in error


async def test_reusing_a_published_message_is_not_an_error(caplog):
    got = []
    async with Runtime(debug_messages=True, handle_signals=False) as rt:
        node = rt.add_node(Node("talker"))
        pub = node.create_publisher(Int32, "/count", 10)
        node.create_subscription(Int32, "/count", got.append, 10)
        msg = Int32()
        for i in range(3):
            msg.data = i  # the rclpy habit: publish copies small messages
            pub.publish(msg)
        await settle(rt)
    assert [m.data for m in got] == [0, 1, 2]
    assert _errors(caplog) == []


async def test_callback_changing_a_shared_message_is_reported(caplog):
    def scribble(image):
        image.data.setflags(write=True)  # defeats the read-only flag: the deeper check still sees it
        image.data[0] = 255

    async with Runtime(debug_messages=True, handle_signals=False) as rt:
        node = rt.add_node(Node("viewer"))
        pub = node.create_publisher(Image, "/camera", 10)
        node.create_subscription(Image, "/camera", scribble, 10)
        pub.publish(Image(height=1, width=4, encoding="mono8", step=4, data=np.zeros(4, np.uint8)))
        await settle(rt)
    [error] = _errors(caplog)
    assert "the callback of subscription /camera changed the message it received" in error


async def test_well_behaved_graph_reports_nothing(caplog):
    got = []
    async with Runtime(debug_messages=True, handle_signals=False) as rt:
        node = rt.add_node(Node("n"))
        pub = node.create_publisher(Int32, "/x", 100)
        node.create_subscription(Int32, "/x", got.append, 100)
        for i in range(20):
            pub.publish(Int32(data=i))
        await settle(rt)
    assert [m.data for m in got] == list(range(20))
    assert _errors(caplog) == []


async def test_assignment_is_type_and_range_checked_under_debug_messages():
    # rclpy's generated setters (rosidl_generator_py _msg.py.em): a wrong type raises TypeError
    # naming the field, an out-of-range integer ValueError; off again when the runtime closes
    from aiorobot.msgs.geometry_msgs import Twist, Vector3
    from aiorobot.msgs.sensor_msgs import JointState
    from aiorobot.msgs.std_msgs import Int32, UInt8

    msg = Int32()
    async with Runtime(debug_messages=True, handle_signals=False):
        with pytest.raises(TypeError, match=r"std_msgs/msg/Int32\.data expects an int"):
            msg.data = "five"
        with pytest.raises(ValueError, match=r"std_msgs/msg/Int32\.data: 1099511627776 is out of range"):
            msg.data = 2**40
        with pytest.raises(ValueError, match="out of range for uint8"):
            UInt8().data = -1
        with pytest.raises(TypeError, match=r"geometry_msgs/msg/Twist\.linear expects a geometry_msgs/msg/Vector3"):
            Twist().linear = 5
        with pytest.raises(TypeError, match=r"JointState\.name\[1\] expects a str"):
            JointState().name = ["a", 2]
        msg.data = 7  # good values pass, and are stored as the constructor stores them
        twist = Twist(linear=Vector3(x=1))
        twist.linear.y = 2  # an int for a float field, as the constructor takes
        assert msg.data == 7 and twist.linear.y == 2.0 and type(twist.linear.y) is float
        state = JointState()
        state.position = [1, 2]
        assert state.position.dtype.name == "float64"
    msg.data = "unchecked again"  # no runtime with debug_messages: assignment is a plain slot write
    assert msg.data == "unchecked again"
    assert "__setattr__" not in Int32.__dict__


async def test_assignment_is_not_checked_without_debug_messages(runtime):
    from aiorobot.msgs.std_msgs import Int32

    msg = Int32()
    msg.data = "five"
    assert msg.data == "five" and "__setattr__" not in Int32.__dict__
