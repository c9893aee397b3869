"""Compression (MCAP zstd chunks), sqlite3 storage, and ``aiorobot bag convert`` with rosbag2's output-options YAML.

Every bag written here is read back by independent readers (rosbags, and the mcap library for
chunk compression), message for message: topic, time and CDR bytes.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from aiorobot import DurabilityPolicy, Node, QoSProfile, Runtime
from aiorobot.bag import BagError, BagReader, BagWriter, OutputBag, Recorder, convert, read_output_options
from aiorobot.cli import main
from aiorobot.msgs import serialize
from aiorobot.msgs.geometry_msgs import Twist
from aiorobot.msgs.std_msgs import String

_MS = 1_000_000


def _rosbags(path: Path) -> list[tuple[str, int, bytes]]:
    from rosbags.rosbag2 import Reader

    with Reader(path) as reader:
        return sorted((c.topic, t, bytes(d)) for c, t, d in reader.messages())


def _source(path: Path) -> list[tuple[str, int, bytes]]:
    """Three topics, one latched, one with a service-event name: what every conversion must carry over."""
    latched = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)
    written = []
    with BagWriter(path) as writer:
        writer.add_topic("/chatter", "std_msgs/msg/String")
        writer.add_topic("/cmd_vel", "geometry_msgs/msg/Twist")
        writer.add_topic("/map_name", "std_msgs/msg/String", latched)
        for i in range(200):
            t = 1_000 * _MS + i * 10 * _MS
            twist = Twist()
            twist.linear.x = i * 0.01
            for topic, data in (("/chatter", serialize(String(data=f"hello {i}" * (i % 7)))), ("/cmd_vel", serialize(twist))):
                writer.write(topic, t, data)
                written.append((topic, t, data))
        writer.write("/map_name", 1_000 * _MS, serialize(String(data="warehouse")))
        written.append(("/map_name", 1_000 * _MS, serialize(String(data="warehouse"))))
    return sorted(written)


async def test_recorder_zstd_chunks_read_back_equal_by_rosbags_and_mcap(tmp_path: Path) -> None:
    from mcap.reader import make_reader
    from mcap.records import Chunk
    from mcap.stream_reader import StreamReader

    out = tmp_path / "zstd"
    async with Runtime(handle_signals=False) as rt:
        pub = rt.add_node(Node("talker")).create_publisher(String, "/chatter", 10)
        recorder = rt.add_node(Recorder(path=str(out), topics=["/chatter"], compression="zstd", max_cache_size=4096))
        await rt.settle()
        sent = [serialize(String(data=f"message {i} " * 20)) for i in range(300)]
        for i in range(300):
            pub.publish(String(data=f"message {i} " * 20))
        await rt.settle()
        recorder.stop()
    from rosbags.rosbag2 import Reader

    with Reader(out) as reader:
        assert [bytes(d) for _, _, d in reader.messages()] == sent
    with open(out / "zstd_0.mcap", "rb") as f:
        data = [m.data for _, _, m in make_reader(f).iter_messages()]
    assert data == sent
    with open(out / "zstd_0.mcap", "rb") as f:
        chunks = [r for r in StreamReader(f, emit_chunks=True).records if isinstance(r, Chunk)]
    assert len(chunks) > 1 and {c.compression for c in chunks} == {"zstd"}
    assert sum(len(c.data) for c in chunks) < sum(c.uncompressed_size for c in chunks) / 3


async def test_recorder_writes_sqlite3_storage(tmp_path: Path) -> None:
    out = tmp_path / "db"
    async with Runtime(handle_signals=False) as rt:
        pub = rt.add_node(Node("talker")).create_publisher(String, "/chatter", 10)
        recorder = rt.add_node(Recorder(path=str(out), topics=["/chatter"], storage="sqlite3"))
        await rt.settle()
        for i in range(5):
            pub.publish(String(data=f"m{i}"))
        await rt.settle()
        recorder.stop()
    assert sorted(p.name for p in out.iterdir()) == ["db_0.db3", "metadata.yaml"]
    assert [d for _, _, d in _rosbags(out)] == [serialize(String(data=f"m{i}")) for i in range(5)]


def test_convert_mcap_to_split_sqlite3_and_back_to_zstd_mcap_round_trips_every_message(tmp_path: Path) -> None:
    written = _source(tmp_path / "src")
    [db3] = convert([tmp_path / "src"], [OutputBag(str(tmp_path / "db3"), storage="sqlite3", all_topics=True, max_bagfile_size=4000)])
    assert db3.messages == len(written) and len(db3.files) > 1 and all(f.endswith(".db3") for f in db3.files)
    assert _rosbags(tmp_path / "db3") == written
    [back] = convert([tmp_path / "db3"], [OutputBag(str(tmp_path / "back"), compression="zstd", all_topics=True)])
    assert _rosbags(tmp_path / "back") == written and back.files == ("back_0.mcap",)
    with BagReader(tmp_path / "back") as reader:  # the latched topic keeps its QoS through both conversions
        qos = {t.name: t.qos for t in reader.topics}
    assert qos["/map_name"].durability is DurabilityPolicy.TRANSIENT_LOCAL and qos["/chatter"].durability is DurabilityPolicy.VOLATILE


def test_convert_splits_by_topic_and_merges_inputs_in_time_order(tmp_path: Path) -> None:
    written = _source(tmp_path / "src")
    with BagWriter(tmp_path / "late") as writer:
        writer.add_topic("/chatter", "std_msgs/msg/String")
        writer.write("/chatter", 1_005 * _MS, serialize(String(data="between")))
    options = tmp_path / "out.yaml"
    options.write_text(
        "output_bags:\n"
        f"- uri: {tmp_path / 'talk'}\n  topics: [/chatter]\n  storage_id: sqlite3\n"
        f"- uri: {tmp_path / 'rest'}\n  all_topics: true\n  exclude_regex: ^/chat\n  storage_preset_profile: zstd_fast\n"
    )
    results = convert([tmp_path / "src", tmp_path / "late"], read_output_options(options))
    assert [r.topics for r in results] == [("/chatter",), ("/cmd_vel", "/map_name")]
    talk = _rosbags(tmp_path / "talk")
    assert talk == sorted([m for m in written if m[0] == "/chatter"] + [("/chatter", 1_005 * _MS, serialize(String(data="between")))])
    assert _rosbags(tmp_path / "rest") == [m for m in written if m[0] != "/chatter"]


@pytest.mark.parametrize(("storage", "mode"), [("mcap", "file"), ("sqlite3", "file"), ("mcap", "message"), ("sqlite3", "message")])
def test_convert_with_rosbag2_file_and_message_compression_round_trips(tmp_path: Path, storage: str, mode: str) -> None:
    written = _source(tmp_path / "src")
    options = tmp_path / "out.yaml"
    options.write_text(f"output_bags:\n- uri: {tmp_path / 'z'}\n  storage_id: {storage}\n  all_topics: true\n"
                       f"  max_bagfile_size: 6000\n  compression_mode: {mode}\n  compression_format: zstd\n")
    [result] = convert([tmp_path / "src"], read_output_options(options))
    assert len(result.files) > 1
    if mode == "file":
        assert all(f.endswith(".zstd") for f in result.files) and not list((tmp_path / "z").glob("*.mcap"))
    assert _rosbags(tmp_path / "z") == written  # rosbags decompresses as rosbag2 does
    with BagReader(tmp_path / "z") as reader:
        assert sorted(reader.messages()) == written
    [back] = convert([tmp_path / "z"], [OutputBag(str(tmp_path / "plain"), all_topics=True)])
    assert _rosbags(tmp_path / "plain") == written


def test_topic_selection_follows_ros2_bag_record() -> None:
    out = OutputBag("x", all_topics=True, exclude_topics=("/b",), exclude_topic_types=("std_msgs/msg/Empty",))
    assert out.selects("/a", "std_msgs/msg/String") and not out.selects("/b", "std_msgs/msg/String")
    assert not out.selects("/c", "std_msgs/msg/Empty")
    assert not out.selects("/srv/_service_event", "example_interfaces/srv/AddTwoInts_Event")  # services only when asked
    assert OutputBag("x", services=("/srv",)).selects("/srv/_service_event", "example_interfaces/srv/AddTwoInts_Event")
    assert OutputBag("x", regex="^/cam").selects("/camera/image", "sensor_msgs/msg/Image")
    assert OutputBag("x", topic_types=("sensor_msgs/msg/Imu",)).selects("/imu", "sensor_msgs/msg/Imu")


@pytest.mark.parametrize(
    ("yaml", "message"),
    [
        ("output_bags:\n- uri: o\n  all_topic: true\n", r"output_bags\[0\]: unknown key 'all_topic'; did you mean 'all_topics'\?$"),
        ("output_bags:\n- uri: o\n  compression_mode: file\n  compression_format: lz4\n",
         r"output_bags\[0\].compression_format: compression_mode 'file' needs 'zstd' \(rosbag2's only format\), found 'lz4'$"),
        ("output_bags:\n- uri: o\n  storage_id: rosbag1\n", r"output_bags\[0\].storage_id: expected 'mcap' or 'sqlite3', found 'rosbag1'$"),
        ("output_bags:\n- storage_id: mcap\n", r"output_bags\[0\].uri: required"),
        ("bags: []\n", r"expected a non-empty list under the top-level key 'output_bags'"),
        ("output_bags:\n- uri: o\n  storage_id: sqlite3\n  compression_format: zstd\n",
         r"zstd without compression_mode is MCAP chunk compression; for storage_id sqlite3 use compression_mode: file or message$"),
    ],
)
def test_bad_output_options_are_one_error_naming_file_and_key(tmp_path: Path, yaml: str, message: str) -> None:
    options = tmp_path / "out.yaml"
    options.write_text(yaml)
    with pytest.raises(BagError, match=message):
        read_output_options(options)


def test_cli_convert_reports_each_output_and_bad_input_is_status_2(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    _source(tmp_path / "src")
    options = tmp_path / "out.yaml"
    options.write_text(f"output_bags:\n- uri: {tmp_path / 'all'}\n  all_topics: true\n- uri: {tmp_path / 'none'}\n  topics: [/nothing]\n")
    assert main(["bag", "convert", "-i", str(tmp_path / "src"), "mcap", "-o", str(options)]) == 0
    captured = capsys.readouterr()
    assert f"{tmp_path / 'all'}: 401 messages on 3 topic(s) in 1 mcap file(s)" in captured.out
    assert f"{tmp_path / 'none'}: the output options select none of the input topics; the bag is empty" in captured.err
    assert main(["bag", "convert", "-i", str(tmp_path / "src"), "-o", str(options)]) == 2  # the outputs exist now
    err = capsys.readouterr().err
    assert err == f"aiorobot bag convert: error: {tmp_path / 'all'}: exists already; choose another uri or remove it\n"
    assert main(["bag", "convert", "-i", str(tmp_path / "src"), "sqlite3", "-o", str(options)]) == 2
    assert "the bag's storage is mcap, not sqlite3" in capsys.readouterr().err
