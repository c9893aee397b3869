"""Runtime(debug_messages=True) reports breaches of the zero-copy contract."""

import logging

import numpy as np

from aiorobot import Node, Runtime
from aiorobot.msgs.sensor_msgs import Image
from aiorobot.msgs.std_msgs import Int32
from aiorobot.testing import settle


def _errors(caplog):
    return [r.getMessage() for r in caplog.records if r.levelno == logging.ERROR]


async def test_reusing_a_published_message_is_reported(caplog):
    async with Runtime(debug_messages=True, handle_signals=False) as rt:
        node = rt.add_node(Node("talker"))
        pub = node.create_publisher(Int32, "/count", 10)
        node.create_subscription(Int32, "/count", lambda m: None, 10)
        msg = Int32()
        for i in range(3):
            msg.data = i  # the classic mistake: one object, mutated and republished
            pub.publish(msg)
        await settle(rt)
    [error] = _errors(caplog)
    assert "debug_messages: a message published on /count was changed after publish" in error


async def test_callback_changing_a_shared_message_is_reported(caplog):
    def scribble(image):
        image.data[0] = 255  # in place: every other subscriber sees this

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
