"""What ``publish`` hands subscribers: a copy with read-only arrays, so a reused message is never corrupted.

Issue 18 item 2: ``msg.linear.x = i; pub.publish(msg)`` three times used to deliver
[2.0, 2.0, 2.0] (the subscribers shared the publisher's object).
"""

import asyncio
import pickle

import numpy as np
import pytest

from aiorobot import GoalResponse, Node, Runtime
from aiorobot.msgs import ReadOnlyMessageError, deserialize, serialize
from aiorobot.msgs.example_interfaces import Fibonacci
from aiorobot.msgs.geometry_msgs import PoseWithCovariance, Twist
from aiorobot.msgs.sensor_msgs import Image, JointState
from aiorobot.testing import settle


def _pair(runtime, msg_type, topic, callback=None):
    node = runtime.add_node(Node("talker"))
    got = []
    node.create_subscription(msg_type, topic, callback or got.append, 10)
    return node.create_publisher(msg_type, topic, 10), got


async def test_reusing_one_message_delivers_each_value(runtime):
    pub, got = _pair(runtime, Twist, "/cmd_vel")
    msg = Twist()
    for i in range(3):
        msg.linear.x = float(i)
        pub.publish(msg)
    await settle(runtime)
    assert [m.linear.x for m in got] == [0.0, 1.0, 2.0]
    assert msg.linear.x == 2.0  # the publisher's object stays its own, still mutable
    msg.angular.z = 1.0


async def test_subscribers_of_one_publish_share_one_copy_with_read_only_arrays_and_lists(runtime):
    node = runtime.add_node(Node("talker"))
    a, b = [], []
    node.create_subscription(JointState, "/joints", a.append, 10)
    node.create_subscription(JointState, "/joints", b.append, 10)
    pub = node.create_publisher(JointState, "/joints", 10)
    sent = JointState(name=["elbow"], position=[0.5])
    pub.publish(sent)
    await settle(runtime)
    [msg] = a
    assert b[0] is msg and msg is not sent and msg == sent
    with pytest.raises(ReadOnlyMessageError, match="copy"):
        msg.name.append("wrist")  # sequences refuse changes
    with pytest.raises(ReadOnlyMessageError):
        msg.name[0] = "wrist"
    with pytest.raises(ValueError, match="read-only"):
        msg.position[0] = 1.0  # numpy arrays are read-only
    sent.position[0] = 2.0  # the publisher's small array was copied: still its own
    sent.name.append("wrist")
    mine = msg.copy()  # the way to change what was received
    mine.position[0] = 1.0
    mine.name.append("wrist")
    mine.header.frame_id = "base"
    assert list(msg.name) == ["elbow"] and msg.position[0] == 0.5 and msg.header.frame_id == ""


async def test_a_tap_that_keeps_nothing_gets_the_publishers_object_and_one_that_keeps_gets_the_copy(runtime):
    """A transport's outbound tap serialises at once: a publisher whose only receivers are such
    taps makes no copy; a tap that may keep the message (a recorder) gets the shared copy."""
    from aiorobot import QoSProfile, lowlevel

    node = runtime.add_node(Node("talker"))
    pub = node.create_publisher(JointState, "/joints", 10)
    passing, kept = [], []
    passer = lowlevel.Tap(JointState, "/joints", QoSProfile(depth=10), passing.append, owner="<wire>", keeps=False)
    lowlevel.add_tap(runtime, passer)
    sent = JointState(name=["elbow"], position=[0.5])
    pub.publish(sent)
    assert passing == [sent] and passing[0] is sent
    keeper = lowlevel.Tap(JointState, "/joints", QoSProfile(depth=10), kept.append, owner="<recorder>")
    lowlevel.add_tap(runtime, keeper)
    pub.publish(sent)
    assert kept[0] is not sent and kept[0] == sent and passing[1] is kept[0]  # one copy for all of them
    with pytest.raises(ReadOnlyMessageError):
        kept[0].name.append("wrist")


def test_a_message_decoded_with_view_is_in_its_delivered_form():
    """``deserialize(..., view=True)`` (what the zenoh transport decodes with) gives read-only
    sequences and arrays, little- and big-endian alike, so nobody needs to copy it again."""
    sent = JointState(name=["elbow"], position=[0.5], velocity=[0.25])
    little = serialize(sent)
    for data in (little, _big_endian_joint_state(sent)):
        msg = deserialize(data, JointState, view=True)
        assert msg == sent
        with pytest.raises(ReadOnlyMessageError):
            msg.name.append("wrist")
        for array in (msg.position, msg.velocity):
            assert not array.flags.writeable
    plain = deserialize(little, JointState)  # the default: a message of one's own
    plain.name.append("wrist")
    plain.position[0] = 1.0


def _big_endian_joint_state(msg):
    """``msg`` (empty header, one name, float64 position and velocity, no effort) in big-endian CDR."""
    import struct

    name = msg.name[0].encode() + b"\0"
    body = struct.pack(">iII", 0, 0, 1) + b"\0"  # stamp, frame_id "" (length 1, NUL)
    body += b"\0" * 3 + struct.pack(">I", 1) + struct.pack(">I", len(name)) + name
    body += b"\0" * (-(len(body)) % 4)
    body += struct.pack(">I", 1)
    body += b"\0" * (-(len(body)) % 8) + struct.pack(">d", msg.position[0])
    body += struct.pack(">I", 1)
    body += b"\0" * (-(len(body)) % 8) + struct.pack(">d", msg.velocity[0])
    body += struct.pack(">I", 0)
    return b"\0\0\0\0" + body


async def test_with_debug_messages_every_field_is_read_only_and_names_the_topic():
    got = []
    async with Runtime(debug_messages=True, handle_signals=False) as rt:
        node = rt.add_node(Node("n"))
        node.create_subscription(JointState, "/joints", got.append, 10)
        node.create_publisher(JointState, "/joints", 10).publish(JointState(name=["elbow"], position=[0.5]))
        await settle(rt)
    [msg] = got
    assert isinstance(msg, JointState)
    with pytest.raises(ReadOnlyMessageError, match="this JointState was published on /joints; .*copy"):
        msg.position = np.zeros(1)
    with pytest.raises(ReadOnlyMessageError, match="this Header was published on /joints"):
        msg.header.frame_id = "base"  # nested messages too
    with pytest.raises(ValueError, match="read-only"):
        msg.position[0] = 1.0


async def test_a_subscriber_that_mutates_an_array_fails_and_others_see_the_original(runtime):
    seen = []

    def scribble(msg):
        msg.covariance[0] = 99.0

    node = runtime.add_node(Node("n"))
    node.create_subscription(PoseWithCovariance, "/pose", scribble, 10)
    node.create_subscription(PoseWithCovariance, "/pose", seen.append, 10)
    pub = node.create_publisher(PoseWithCovariance, "/pose", 10)
    pub.publish(PoseWithCovariance())
    await settle(runtime)
    assert seen[0].covariance[0] == 0.0


async def test_large_arrays_are_shared_read_only(runtime):
    pub, got = _pair(runtime, Image, "/camera")
    pixels = np.arange(640 * 480 * 3, dtype=np.uint8)
    msg = Image(height=480, width=640, encoding="rgb8", step=640 * 3, data=pixels)
    pub.publish(msg)
    await settle(runtime)
    [received] = got
    assert received.data is pixels  # zero-copy: the very buffer
    assert not pixels.flags.writeable  # and read-only on both sides
    with pytest.raises(ValueError, match="read-only"):
        msg.data[0] = 1
    msg.data = np.zeros_like(pixels)  # a new buffer for the next frame is fine
    pub.publish(msg)
    await settle(runtime)
    assert got[1].data is msg.data and got[0].data is pixels and pixels[1] == 1


async def test_small_arrays_are_copied_so_the_publisher_may_change_them(runtime):
    pub, got = _pair(runtime, PoseWithCovariance, "/pose")
    msg = PoseWithCovariance()
    for i in range(2):
        msg.covariance[0] = float(i)  # in place, after the previous publish
        pub.publish(msg)
    await settle(runtime)
    assert [m.covariance[0] for m in got] == [0.0, 1.0]
    assert msg.covariance.flags.writeable


async def test_republishing_a_received_message_shares_its_large_arrays(runtime):
    node = runtime.add_node(Node("relay"))
    out, first = [], []
    relay = node.create_publisher(Image, "/out", 10)
    node.create_subscription(Image, "/in", relay.publish, 10)
    node.create_subscription(Image, "/out", out.append, 10)
    node.create_subscription(Image, "/in", first.append, 10)
    node.create_publisher(Image, "/in", 10).publish(Image(data=np.zeros(1 << 16, np.uint8)))
    await settle(runtime)
    assert out[0] == first[0] and out[0].data is first[0].data


def test_read_only_twins_encode_pickle_and_compare_as_their_type():
    from aiorobot.msgs._classgen import freezer

    msg = JointState(name=["a"], position=[1.0], velocity=[2.0])
    frozen = JointState._fz(msg, freezer("/joints"))
    assert frozen == msg and msg == frozen
    assert serialize(frozen) == serialize(msg)
    assert deserialize(serialize(frozen), JointState) == msg
    back = pickle.loads(pickle.dumps(frozen))
    assert back == msg and not back._frozen
    back.name.append("b")
    back.position[0] = 3.0
    rebuilt = type(frozen)(name=["c"])  # e.g. tf2's do_transform builds type(msg)(...)
    rebuilt.name.append("d")
    assert rebuilt.name == ["c", "d"]


async def test_fibonacci_feedback_reused_after_publish_feedback(runtime):
    # ros2/examples action_server (rclpy): one feedback message, changed after every
    # publish_feedback; each feedback received must show the sequence as it was then.
    class Server(Node):
        def __init__(self):
            super().__init__("fib_server")
            self.create_action_server(Fibonacci, "fibonacci", self.execute,
                                      goal_callback=lambda goal: GoalResponse.ACCEPT)

        async def execute(self, gh):
            feedback = Fibonacci.Feedback(sequence=[0, 1])
            for i in range(1, gh.request.order):
                feedback.sequence = np.append(feedback.sequence, feedback.sequence[i] + feedback.sequence[i - 1])
                gh.publish_feedback(feedback)
                feedback.sequence[0] = -1  # an in-place change after publishing
                feedback.sequence[0] = 0
                await asyncio.sleep(0)
            gh.succeed()
            return Fibonacci.Result(sequence=feedback.sequence)

    runtime.add_node(Server())
    client = runtime.add_node(Node("fib_client")).create_action_client(Fibonacci, "fibonacci")
    assert await client.wait_for_server(timeout_sec=10)
    seen = []
    handle = await client.send_goal(Fibonacci.Goal(order=5), feedback_callback=seen.append)
    result = await handle.result()
    await asyncio.sleep(0)
    assert list(result.sequence) == [0, 1, 1, 2, 3, 5]
    assert [list(m.feedback.sequence) for m in seen] == [[0, 1, 1], [0, 1, 1, 2], [0, 1, 1, 2, 3],
                                                        [0, 1, 1, 2, 3, 5]]


async def test_a_list_assigned_to_an_array_field_arrives_as_a_read_only_array_of_the_fields_type(runtime):
    # ros2/examples' Fibonacci server does `feedback.sequence = [0, 1]` then appends to it before publishing
    from aiorobot.msgs.std_msgs import Int32MultiArray

    pub, got = _pair(runtime, Int32MultiArray, "/numbers")
    msg = Int32MultiArray()
    msg.data = [0, 1]
    msg.data.append(1)
    pub.publish(msg)
    await settle(runtime)
    assert got[0].data.dtype == np.int32 and got[0].data.tolist() == [0, 1, 1]
    assert not got[0].data.flags.writeable
