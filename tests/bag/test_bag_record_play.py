"""Recording into rosbag2 (MCAP) directories and playing them back, checked with rosbags' reader."""

from __future__ import annotations

import asyncio
from pathlib import Path

import numpy as np
import pytest

from aiorobot import Node, QoSProfile, Runtime
from aiorobot.bag import BagError, BagReader, Player, Recorder
from aiorobot.msgs.geometry_msgs import Twist, Vector3
from aiorobot.msgs.sensor_msgs import Image
from aiorobot.msgs.std_msgs import String


def _read_back(path: Path) -> dict[str, list[tuple[int, object]]]:
    """Every message of the bag, decoded by rosbags (an independent reader), per topic."""
    from rosbags.highlevel import AnyReader
    from rosbags.typesys import Stores, get_typestore

    out: dict[str, list[tuple[int, object]]] = {}
    with AnyReader([path], default_typestore=get_typestore(Stores.ROS2_JAZZY)) as reader:
        for conn, t_ns, raw in reader.messages():
            out.setdefault(conn.topic, []).append((t_ns, reader.deserialize(raw, conn.msgtype)))
    return out


async def test_recorder_loses_nothing_and_rosbags_reads_every_message_back(tmp_path: Path) -> None:
    bag = tmp_path / "run"
    image = np.arange(640 * 480 * 3, dtype=np.uint64).astype(np.uint8)
    async with Runtime(handle_signals=False) as rt:
        rec = Recorder(path=str(bag))
        rt.add_node(rec)
        src = Node("src")
        twist_pub = src.create_publisher(Twist, "/cmd_vel", QoSProfile(depth=1))
        image_pub = src.create_publisher(Image, "/camera/image_raw", 1)
        rt.add_node(src)
        msg = Twist()
        for i in range(500):  # one reused message object, the rclpy habit: the bag must hold each value
            msg.linear.x = float(i)
            twist_pub.publish(msg)
            if i % 100 == 0:
                image_pub.publish(Image(height=480, width=640, encoding="rgb8", step=1920, data=image))
        await rt.spin(duration_sec=0.05)
    assert rec.statistics().messages == 505
    back = _read_back(bag)
    assert [m.linear.x for _, m in back["/cmd_vel"]] == [float(i) for i in range(500)]
    assert len(back["/camera/image_raw"]) == 5
    assert np.array_equal(back["/camera/image_raw"][0][1].data, image)
    stamps = [t for t, _ in back["/cmd_vel"]]
    assert stamps == sorted(stamps)


async def test_recording_all_topics_taps_a_publisher_created_after_the_recorder(tmp_path: Path) -> None:
    bag = tmp_path / "late"
    async with Runtime(handle_signals=False) as rt:
        rt.add_node(Recorder(path=str(bag), exclude="^/rosout$"))
        late = Node("late")
        rt.add_node(late)
        pub = late.create_publisher(String, "/late", 10)
        pub.publish(String(data="first"))  # published at once: must not be missed
        pub.publish(String(data="second"))
        await rt.spin(duration_sec=0.02)
    assert [m.data for _, m in _read_back(bag)["/late"]] == ["first", "second"]


async def test_named_topics_only_and_a_transient_local_topic_recorded_from_its_start(tmp_path: Path) -> None:
    from aiorobot import DurabilityPolicy

    bag = tmp_path / "named"
    async with Runtime(handle_signals=False) as rt:
        src = Node("src")
        latched = src.create_publisher(String, "/map_info", QoSProfile(durability=DurabilityPolicy.TRANSIENT_LOCAL, depth=1))
        other = src.create_publisher(String, "/other", 10)
        rt.add_node(src)
        latched.publish(String(data="latched before the recorder"))
        rt.add_node(Recorder(path=str(bag), topics=["/map_info"]))
        other.publish(String(data="not recorded"))
        await rt.spin(duration_sec=0.02)
    back = _read_back(bag)
    assert list(back) == ["/map_info"]
    assert back["/map_info"][0][1].data == "latched before the recorder"




async def test_play_with_clock_gives_sim_time_nodes_the_recorded_time(tmp_path: Path) -> None:
    from aiorobot.bag import BagWriter
    from aiorobot.msgs import serialize

    bag = tmp_path / "clocked"
    base = 1_700_000_000 * 10**9
    with BagWriter(bag) as writer:
        writer.add_topic("/odom_x", "std_msgs/msg/Float64")
        from aiorobot.msgs.std_msgs import Float64

        for i in range(5):
            writer.write("/odom_x", base + i * 20_000_000, serialize(Float64(data=float(i))))
    seen: list[tuple[int, float]] = []
    done = asyncio.Event()

    class Listener(Node):
        def __init__(self) -> None:
            super().__init__("listener")
            self.create_subscription(Float64, "/odom_x", self.on_msg, 10)

        def on_msg(self, msg: Float64) -> None:
            seen.append((self.now().nanoseconds, msg.data))
            if len(seen) == 5:
                done.set()

    again = tmp_path / "again"
    async with Runtime(handle_signals=False, use_sim_time=True) as rt:
        rt.add_node(Recorder(path=str(again), topics=["/odom_x"]))  # receive stamps on sim time
        rt.add_node(Listener())
        player = Player(path=str(bag), rate=20.0, clock=True)
        rt.add_node(player)
        await asyncio.wait_for(done.wait(), 30)
        assert await player.wait_for_completion(30)
    assert [v for _, v in seen] == [0.0, 1.0, 2.0, 3.0, 4.0]
    assert all(now >= base + i * 20_000_000 for i, (now, _) in enumerate(seen))
    # Recorded again on the player's /clock: the very stamps of the first recording.
    assert [t for t, _ in _read_back(again)["/odom_x"]] == [base + i * 20_000_000 for i in range(5)]


def test_a_directory_that_is_not_a_bag_gets_one_clear_error(tmp_path: Path) -> None:
    with pytest.raises(BagError, match=r"not a rosbag2 directory \(no metadata.yaml\)$"):
        BagReader(tmp_path)
    with pytest.raises(BagError, match="no such bag directory"):
        BagReader(tmp_path / "missing")


def test_offered_qos_keeps_liveliness_and_lease():
    from rosbags.interfaces import QosLiveliness

    from aiorobot import Duration, LivelinessPolicy, QoSProfile
    from aiorobot.bag._metadata import qos_to_bag

    qos = qos_to_bag(QoSProfile(liveliness=LivelinessPolicy.MANUAL_BY_TOPIC, liveliness_lease_duration=Duration(seconds=2.5)))
    assert qos.liveliness == QosLiveliness.MANUAL_BY_TOPIC
    assert (qos.liveliness_lease_duration.sec, qos.liveliness_lease_duration.nsec) == (2, 500_000_000)
    assert qos_to_bag(QoSProfile()).liveliness == QosLiveliness.AUTOMATIC
