"""Bags as ``ros2 bag record`` writes them (MCAP and sqlite3) read and play completely.

Each bag is built by ``_ros2_bags`` without aiorobot's writer, with the QoS mismatch between
``metadata.yaml`` and the storage that ros2-recorded bags have, and counted by an independent
reader (``mcap`` / ``sqlite3``) straight from the storage file.
"""

from __future__ import annotations

import asyncio
import logging
from pathlib import Path
from typing import Any

import pytest

from aiorobot import Node, QoSProfile, Runtime
from aiorobot.bag import BagReader, Player
from aiorobot.msgs import deserialize

from ._ros2_bags import METADATA_QOS_ARGS, STORAGE_QOS, BagTopic, Ros2Bag, qos_text, ros2_bag, stored_counts, typestore, write_mcap

T0 = 1_586_406_456_763_032_325  # cdr_test's first stamp: the float of it in seconds is not exact

SRV_TEXT = "int64 a\nint64 b\n---\nint64 sum\n"


def _talker_like(tmp_path: Path, storage: str, *, with_definitions: bool = True, pkg: str = "", **kwargs: Any) -> Ros2Bag:
    """A plain topic, a service-event topic, an old-style type name and an empty-definition type.

    The test types are in packages named after ``pkg`` (default ``bag<storage>``): types are
    registered once per process, so a test that needs them unknown uses its own name.
    """
    from rosbags.typesys import Stores, get_typestore

    pkg = pkg or f"bag{storage}"
    store = typestore(pkg)
    jazzy = get_typestore(Stores.ROS2_JAZZY)
    String = jazzy.types["std_msgs/msg/String"]
    chatter = BagTopic("/topic", "std_msgs/msg/String", "string data\n" if with_definitions else None,
                       [(T0 + i * 10_000_000, bytes(jazzy.serialize_cdr(String(data=f"Hello World: {i}"), "std_msgs/msg/String")))
                        for i in range(10)])
    Req, Resp, Event = (store.types[f"{pkg}_srvs/msg/Add{x}"] for x in ("Request", "Response", "Event"))
    Info = store.types["service_msgs/msg/ServiceEventInfo"]
    Time = store.types["builtin_interfaces/msg/Time"]
    import numpy as np

    events = []
    for k, kind in enumerate((0, 1, 2, 3)):  # request sent / received, response sent / received
        info = Info(event_type=kind, stamp=Time(sec=1, nanosec=k), client_gid=np.full(16, 7, np.uint8), sequence_number=1)
        ev = Event(info=info, request=[Req(a=2, b=3)] if kind < 2 else [], response=[Resp(sum=5)] if kind >= 2 else [])
        events.append((T0 + 5_000_000 + k, bytes(store.serialize_cdr(ev, f"{pkg}_srvs/msg/AddEvent"))))
    service = BagTopic("/add/_service_event", f"{pkg}_srvs/srv/Add_Event", SRV_TEXT if with_definitions else None, events)
    Point2 = store.types[f"{pkg}_old/msg/Point2"]
    old = BagTopic("/old", f"{pkg}_old/Point2", "float64 x\nfloat64 y\n" if with_definitions else None,
                   [(T0 + 1 + i, bytes(store.serialize_cdr(Point2(x=float(i), y=-1.0), f"{pkg}_old/msg/Point2"))) for i in range(3)])
    Nothing = store.types[f"{pkg}_empty/msg/Nothing"]
    empty = BagTopic("/nothing", f"{pkg}_empty/msg/Nothing", "" if with_definitions else None,
                     [(T0 + 2 + i, bytes(store.serialize_cdr(Nothing(structure_needs_at_least_one_member=0), f"{pkg}_empty/msg/Nothing")))
                      for i in range(2)])
    return ros2_bag(tmp_path / f"talker_{storage}", storage, [chatter, service, old, empty], **kwargs)


def test_the_fixture_has_the_qos_mismatch_of_ros2_recorded_bags() -> None:
    from rosbags.rosbag2.metadata import parse_qos
    from ruamel.yaml import YAML

    in_metadata = parse_qos(YAML(typ="safe").load(qos_text(*METADATA_QOS_ARGS)))
    assert parse_qos(STORAGE_QOS) != in_metadata  # rosbags pairs the two by equality


@pytest.mark.parametrize("storage", ["mcap", "sqlite3"])
def test_every_message_of_a_ros2_recorded_bag_is_read_and_decodes(tmp_path: Path, storage: str) -> None:
    bag = _talker_like(tmp_path, storage)
    expected = stored_counts(bag)
    assert expected == {"/topic": 10, "/add/_service_event": 4, "/old": 3, "/nothing": 2}
    pkg = f"bag{storage}"
    with BagReader(bag.path) as reader:
        assert reader.warnings == []
        assert reader.storage == storage
        assert {t.name: t.message_count for t in reader.topics} == expected
        got: dict[str, list[Any]] = {}
        for topic, t_ns, data in reader.messages():
            got.setdefault(topic, []).append((t_ns, deserialize(data, reader.message_type(topic))))
    assert {k: len(v) for k, v in got.items()} == expected
    assert [m.data for _, m in got["/topic"]] == [f"Hello World: {i}" for i in range(10)]
    events = [m for _, m in got["/add/_service_event"]]
    assert type(events[0]).__msgtype__ == f"{pkg}_srvs/srv/Add_Event"  # registered from the bag's .srv text
    assert [e.info.event_type for e in events] == [0, 1, 2, 3]
    assert [(r.a, r.b) for r in events[0].request] == [(2, 3)] and [r.sum for r in events[3].response] == [5]
    assert [(m.x, m.y) for _, m in got["/old"]] == [(0.0, -1.0), (1.0, -1.0), (2.0, -1.0)]
    assert type(got["/old"][0][1]).__msgtype__ == f"{pkg}_old/msg/Point2"  # the old-style name, completed
    assert len(got["/nothing"]) == 2  # an empty definition is a definition
    times = [t for v in got.values() for t, _ in v]
    assert min(times) == T0


@pytest.mark.parametrize("storage", ["mcap", "sqlite3"])
def test_fewer_messages_than_metadata_counts_is_said_per_topic_with_the_reason(
    tmp_path: Path, storage: str, caplog: pytest.LogCaptureFixture
) -> None:
    from rosbags.typesys import Stores, get_typestore

    jazzy = get_typestore(Stores.ROS2_JAZZY)
    data = bytes(jazzy.serialize_cdr(jazzy.types["std_msgs/msg/String"](data="x"), "std_msgs/msg/String"))
    short = BagTopic("/short", "std_msgs/msg/String", "string data\n", [(T0 + i, data) for i in range(3)], metadata_count=5)
    whole = BagTopic("/whole", "std_msgs/msg/String", "string data\n", [(T0 + 10, data)])
    bag = ros2_bag(tmp_path / "lying", storage, [short, whole], metadata_only=[("/ghost", "std_msgs/msg/String", 4)])
    with caplog.at_level(logging.WARNING, logger="aiorobot.bag"), BagReader(bag.path) as reader:
        read = sum(1 for _ in reader.messages())
        warnings = reader.warnings
    assert read == 4 == sum(stored_counts(bag).values())
    assert warnings == [
        f"{bag.path}: topic /short: metadata.yaml counts 5 messages, its storage files hold only 3; "
        "metadata.yaml is wrong or a file was cut short",
        f"{bag.path}: topic /ghost: metadata.yaml counts 4 messages, no storage file holds the topic",
    ]
    assert [r.getMessage() for r in caplog.records] == [f"bag: {w}" for w in warnings]


def test_a_topic_whose_type_cannot_be_known_is_skipped_by_the_player_with_its_reason(tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    """sqlite3 bags written before Iron store no definitions: an unknown type is named, with why."""
    bag = _talker_like(tmp_path, "sqlite3", with_definitions=False, pkg="bagnodefs")
    with BagReader(bag.path) as reader:
        assert sum(1 for _ in reader.messages()) == 19  # the reader still yields every message
        assert reader.message_type("/topic") is not None  # a type aiorobot knows needs no definition
        assert reader.message_type("/old") is None
        assert reader.type_problem("/old") == "type bagnodefs_old/Point2 is unknown to aiorobot and the bag holds no definition of it"

    async def build() -> list[str]:
        async with Runtime(handle_signals=False):
            with caplog.at_level(logging.WARNING):
                Player(path=str(bag.path))
            return [r.getMessage() for r in caplog.records if "skipped" in r.getMessage()]

    lines = asyncio.run(build())
    assert "/old: type bagnodefs_old/Point2 is unknown to aiorobot and the bag holds no definition of it; its 3 messages are skipped" in lines
    assert len(lines) == 3  # /old, /nothing, /add/_service_event: one line each


@pytest.mark.parametrize("storage", ["mcap", "sqlite3"])
async def test_play_starts_at_the_first_message_even_before_metadata_starting_time(tmp_path: Path, storage: str) -> None:
    """rosbag2's wbag: metadata.yaml's starting_time (2623) is later than its first messages (1000)."""
    bag = _talker_like(tmp_path, storage, starting_time=T0 + 50_000_000)
    got: list[str] = []
    done = asyncio.Event()

    class Sink(Node):
        def __init__(self) -> None:
            super().__init__("sink")
            from aiorobot.msgs.std_msgs import String

            self.create_subscription(String, "/topic", self.on_msg, QoSProfile(depth=100))

        def on_msg(self, m: Any) -> None:
            got.append(m.data)

    async with Runtime(handle_signals=False) as rt:
        rt.add_node(Sink())
        player = Player(path=str(bag.path), rate=50.0)
        rt.add_node(player)
        assert player.reader.start_ns == T0
        assert await player.wait_for_completion(30)
        stats = player.statistics()
        done.set()
    assert got == [f"Hello World: {i}" for i in range(10)]
    assert stats.published == 19 and stats.skipped == 0
    assert stats.subscribers == 1 and stats.topics_matched == 1


def test_reindex_of_ros2_recorded_mcap_files_reads_back_every_message(tmp_path: Path) -> None:
    """rosbag2's reindex_test_bags/multiple_files: three whole MCAP files and no metadata.yaml."""
    from rosbags.highlevel import AnyReader
    from rosbags.rosbag2 import Reader
    from rosbags.typesys import Stores, get_typestore

    from aiorobot.bag import reindex

    bag = tmp_path / "multiple_files"
    parts = []
    for i, n in enumerate((5, 5, 2)):
        part = _talker_like(tmp_path / f"part{i}", "mcap")
        for topic in part.topics:
            topic.messages = [(t + i * 1_000_000_000, d) for t, d in topic.messages[:n]]
        parts.append(part)
    bag.mkdir()
    for i, part in enumerate(parts):  # rewrite each part's messages into multiple_files_<i>.mcap, no metadata.yaml
        write_mcap(bag / f"multiple_files_{i}.mcap", part.topics)
    before = {p.name: p.read_bytes() for p in bag.iterdir()}
    total = sum(len(t.messages) for part in parts for t in part.topics)
    result = reindex(bag)
    assert (result.files, result.messages, result.damaged) == (3, total, 0)
    assert {p.name: p.read_bytes() for p in bag.iterdir() if p.suffix == ".mcap"} == before  # whole files are left alone
    with Reader(bag) as reader:  # rosbags' rosbag2 reader pairs metadata.yaml's QoS with the channels' by equality
        assert sum(1 for _ in reader.messages()) == total
    plain = tmp_path / "plain"  # AnyReader parses every definition (not a .srv text): the String topic alone
    plain.mkdir()
    for i, part in enumerate(parts):
        write_mcap(plain / f"plain_{i}.mcap", [t for t in part.topics if t.name == "/topic"])
    assert reindex(plain).messages == 12
    with AnyReader([plain], default_typestore=get_typestore(Stores.ROS2_JAZZY)) as reader:
        assert [reader.deserialize(raw, c.msgtype).data for c, _, raw in reader.messages()] == [
            f"Hello World: {i}" for n in (5, 5, 2) for i in range(n)
        ]
    with BagReader(bag) as reader:
        assert reader.warnings == []
        assert sum(1 for _ in reader.messages()) == total


@pytest.mark.parametrize("storage", ["mcap", "sqlite3"])
def test_bag_info_of_a_ros2_recorded_bag_prints_seconds_from_the_integer_stamps(
    tmp_path: Path, storage: str, capsys: pytest.CaptureFixture[str]
) -> None:
    from aiorobot.cli import main

    bag = _talker_like(tmp_path, storage)
    assert main(["bag", "info", str(bag.path)]) == 0
    out = capsys.readouterr().out
    assert "Start:             Apr 09 2020 04:27:36.763032325 (1586406456.763032325)" in out  # a float prints ...436
    assert "End:               Apr 09 2020 04:27:36.853032325 (1586406456.853032325)" in out
    assert "Duration:          0.090000000s" in out
    assert f"Storage id:        {storage}" in out and "Messages:          19" in out
    assert f"Topic: /add/_service_event | Type: bag{storage}_srvs/srv/Add_Event | Count: 4" in out


async def test_play_starts_at_a_message_stamped_0_that_the_mcap_statistics_leave_out(tmp_path: Path) -> None:
    """rosbag2's convert_a: a_empty's first message is stamped 0, its MCAP statistics start at 1000000."""
    from rosbags.typesys import Stores, get_typestore

    jazzy = get_typestore(Stores.ROS2_JAZZY)
    msgs = [(t, bytes(jazzy.serialize_cdr(jazzy.types["std_msgs/msg/String"](data=str(t)), "std_msgs/msg/String")))
            for t in (0, 1_000_000, 2_000_000)]
    bag = ros2_bag(tmp_path / "zero", "mcap", [BagTopic("/z", "std_msgs/msg/String", "string data\n", msgs)],
                   starting_time=0, statistics_start=1_000_000)
    async with Runtime(handle_signals=False) as rt:
        player = Player(path=str(bag.path), rate=100.0)
        rt.add_node(player)
        assert player.reader.start_ns == 0
        assert await player.wait_for_completion(30)
    assert player.statistics().published == 3


def _one_message_bag(tmp_path: Path) -> Path:
    from rosbags.typesys import Stores, get_typestore

    jazzy = get_typestore(Stores.ROS2_JAZZY)
    data = bytes(jazzy.serialize_cdr(jazzy.types["std_msgs/msg/String"](data="x"), "std_msgs/msg/String"))
    return ros2_bag(tmp_path / "one", "mcap", [BagTopic("/one", "std_msgs/msg/String", "string data\n", [(T0, data)])]).path


async def test_loop_of_a_one_message_bag_leaves_the_loop_free(tmp_path: Path) -> None:
    """Every pass of a one-message bag is due at once: the player used to hold the loop for ever."""
    async with Runtime(handle_signals=False) as rt:
        player = Player(path=str(_one_message_bag(tmp_path)), loop=True)
        rt.add_node(player)
        turns = 0
        while player.statistics().loops < 200:
            await asyncio.sleep(0)  # never returned while the player looped
            turns += 1
        assert turns >= 1 and not player.done
    assert player.done  # shutdown stopped it


def test_bag_play_reports_matched_subscribers_and_warns_in_one_line_when_none(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from aiorobot.cli import main

    bag = _one_message_bag(tmp_path)
    assert main(["bag", "play", "--transport", "local", str(bag)]) == 0
    err = capsys.readouterr().err.splitlines()
    assert err[-2:] == [
        f"played 1 messages from {bag} to 0 subscriber(s) on 0 of 1 topic(s)",
        "aiorobot bag play: warning: no subscriber matched any of the 1 topic(s) played (in this process); nothing received these messages",
    ]


@pytest.mark.parametrize("mode", ["file", "message"])
def test_zstd_compressed_bags_read_every_message(tmp_path: Path, mode: str) -> None:
    """ros2 bag record --compression-mode file|message --compression-format zstd (written here by rosbags)."""
    from rosbags.rosbag2 import StoragePlugin, Writer
    from rosbags.rosbag2.enums import CompressionFormat, CompressionMode
    from rosbags.typesys import Stores, get_typestore

    jazzy = get_typestore(Stores.ROS2_JAZZY)
    bag = tmp_path / f"zstd_{mode}"
    writer = Writer(bag, version=9, storage_plugin=StoragePlugin.MCAP)
    writer.set_compression(CompressionMode[mode.upper()], CompressionFormat.ZSTD)
    with writer:
        conn = writer.add_connection("/chatter", "std_msgs/msg/String", typestore=jazzy)
        for i in range(5):
            writer.write(conn, T0 + i, bytes(jazzy.serialize_cdr(jazzy.types["std_msgs/msg/String"](data=f"m{i}"), "std_msgs/msg/String")))
    with BagReader(bag) as reader:
        got = [deserialize(data, reader.message_type(topic)).data for topic, _, data in reader.messages()]
        assert reader.warnings == [] and reader.start_ns == T0
    assert got == [f"m{i}" for i in range(5)]
