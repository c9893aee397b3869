"""``aiorobot bag info|reindex|record|play`` on directories; bad input gets one line and a non-zero status."""

from __future__ import annotations

import asyncio
from pathlib import Path

import pytest

from aiorobot import Node, Runtime
from aiorobot.bag import BagReader, BagWriter, Player
from aiorobot.cli import main
from aiorobot.msgs import serialize
from aiorobot.msgs.std_msgs import String


def _bag(path: Path, n: int = 3) -> Path:
    with BagWriter(path, chunk_size=4096) as writer:
        writer.add_topic("/chatter", "std_msgs/msg/String")
        for i in range(n):
            writer.write("/chatter", 1_000_000_000 + i * 10_000_000, serialize(String(data=f"hello {i}")))
    return path


def test_info_prints_files_duration_and_topics_like_ros2_bag_info(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bag = _bag(tmp_path / "talk")
    assert main(["bag", "info", str(bag)]) == 0
    out = capsys.readouterr().out
    assert "Files:             talk_0.mcap" in out
    assert "Storage id:        mcap" in out
    assert "Duration:          0.020000000s" in out
    assert "Messages:          3" in out
    assert "Topic: /chatter | Type: std_msgs/msg/String | Count: 3 | Serialization Format: cdr" in out


def test_info_on_something_that_is_not_a_bag_is_one_line_and_status_1(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    (tmp_path / "notes.txt").write_text("hi")
    assert main(["bag", "info", str(tmp_path / "notes.txt")]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "expected a rosbag2 directory" in err


def test_a_truncated_mcap_is_reported_with_the_reindex_hint_and_reindex_repairs_it(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bag = _bag(tmp_path / "cut", n=2000)
    mcap = bag / "cut_0.mcap"
    data = mcap.read_bytes()
    mcap.write_bytes(data[: len(data) * 2 // 3])  # the summary and footer are gone
    assert main(["bag", "info", str(bag)]) == 1
    assert "aiorobot bag reindex" in capsys.readouterr().err
    assert main(["bag", "reindex", str(bag)]) == 0
    assert "damaged file(s) repaired" in capsys.readouterr().out
    with BagReader(bag) as reader:
        assert 0 < reader.message_count < 2000


def test_bad_arguments_are_one_line_errors(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["bag", "play", "x", "--rate", "0"]) == 2
    assert "expected a positive number, found '0'" in capsys.readouterr().err
    assert main(["bag", "play", "x", "--remap", "nonsense"]) == 2
    assert "expected FROM:=TO" in capsys.readouterr().err
    assert main(["bag", "record", "--transport", "local", "--duration", "0.1"]) == 1
    assert "expected topics to record, or -a" in capsys.readouterr().err


async def test_a_type_aiorobot_does_not_know_plays_from_the_definition_in_the_bag(tmp_path: Path) -> None:
    """A bag from elsewhere with a custom type: the player registers it from the bag's schema."""
    from rosbags.rosbag2 import StoragePlugin, Writer
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    store = get_typestore(Stores.ROS2_JAZZY)
    store.register(get_types_from_msg("string label\ngeometry_msgs/Point where\n", "bagtest_msgs/msg/Spot"))
    Spot = store.types["bagtest_msgs/msg/Spot"]
    Point = store.types["geometry_msgs/msg/Point"]
    bag = tmp_path / "foreign"
    with Writer(bag, version=9, storage_plugin=StoragePlugin.MCAP) as writer:
        conn = writer.add_connection("/spots", "bagtest_msgs/msg/Spot", typestore=store)
        for i in range(3):
            raw = store.serialize_cdr(Spot(label=f"s{i}", where=Point(x=float(i), y=0.0, z=0.0)), "bagtest_msgs/msg/Spot")
            writer.write(conn, 10 + i, bytes(raw))
    got: list[tuple[str, float]] = []
    done = asyncio.Event()
    async with Runtime(handle_signals=False) as rt:
        player = Player(path=str(bag), rate=100.0)
        from aiorobot import msgs

        SpotType = msgs.get("bagtest_msgs/msg/Spot")

        class Sink(Node):
            def __init__(self) -> None:
                super().__init__("sink")
                self.create_subscription(SpotType, "/spots", self.on_msg, 10)

            def on_msg(self, m: object) -> None:
                got.append((m.label, m.where.x))  # type: ignore[attr-defined]
                if len(got) == 3:
                    done.set()

        rt.add_node(Sink())
        rt.add_node(player)
        await asyncio.wait_for(done.wait(), 30)
    assert got == [("s0", 0.0), ("s1", 1.0), ("s2", 2.0)]
