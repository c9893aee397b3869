"""Runtime(debug_messages=True) reports breaches of the zero-copy contract."""

import logging

import numpy as np

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
