"""Snapshot (flight recorder) mode: the last max_cache_size bytes of every topic, written on ~/snapshot or a trigger."""

from __future__ import annotations

import asyncio
import subprocess
import sys
from pathlib import Path

import pytest

from aiorobot import Node, Runtime
from aiorobot.bag import BagReader, Recorder, SnapshotBuffer
from aiorobot.msgs import rosbag2_interfaces as srv, serialize
from aiorobot.msgs.std_msgs import Empty, String
from aiorobot.testing import SimClock

_MS = 1_000_000
PAYLOAD = String(data="x" * 96)
SIZE = len(serialize(PAYLOAD))


def test_buffer_keeps_the_newest_messages_within_its_bytes() -> None:
    ring = SnapshotBuffer(3 * SIZE)
    for i in range(5):
        ring.push("/a", i, serialize(PAYLOAD))
    ring.push("/huge", 9, b"\0" * (4 * SIZE))  # larger than the whole buffer: cannot be held
    stats = ring.statistics()
    assert (stats.messages, stats.bytes, stats.dropped) == (3, 3 * SIZE, 3)
    assert [t for _, t, _ in ring.take()] == [2, 3, 4]
    assert ring.take() == [] and ring.statistics().bytes == 0
    with pytest.raises(ValueError, match=r"max_bytes must be > 0, found 0"):
        SnapshotBuffer(0)


def _read(path: Path) -> dict[str, list[int]]:
    """Receive times per topic as rosbags (an independent reader) sees them."""
    from rosbags.highlevel import AnyReader

    out: dict[str, list[int]] = {}
    with AnyReader([path]) as reader:
        for conn, t, raw in reader.messages():
            assert reader.deserialize(raw, conn.msgtype).data == PAYLOAD.data
            out.setdefault(conn.topic, []).append(t)
    return out


async def _wait_for(predicate: object, what: str) -> None:
    for _ in range(500):  # generous bound; the writer thread usually needs a few ms
        if predicate():  # type: ignore[operator]
            return
        await asyncio.sleep(0.01)
    raise AssertionError(f"timed out waiting for {what}")


async def test_snapshot_service_writes_the_last_second_of_every_topic_as_a_readable_bag(tmp_path: Path) -> None:
    out = tmp_path / "flight"
    async with Runtime(use_sim_time=True, handle_signals=False) as rt:
        sim = SimClock(rt)
        talker = rt.add_node(Node("talker"))
        fast = talker.create_publisher(String, "/fast", 10)
        slow = talker.create_publisher(String, "/slow", 10)
        trigger = talker.create_publisher(Empty, "/incident", 1)
        # one second of recording: 100 messages of /fast (100 Hz) and 10 of /slow (10 Hz)
        recorder = rt.add_node(Recorder(path=str(out), topics=["/fast", "/slow"], snapshot_mode=True,
                                        max_cache_size=110 * SIZE, snapshot_trigger="/incident"))
        probe = rt.add_node(Node("probe"))
        await rt.settle()
        for k in range(1, 501):  # 5 s
            await sim.set(k * 0.01)
            fast.publish(PAYLOAD)
            if k % 10 == 0:
                slow.publish(PAYLOAD)
        assert not (out / "metadata.yaml").exists()  # nothing written before a snapshot
        client = probe.create_client(srv.Snapshot, "/recorder/snapshot")
        assert await client.wait_for_service(timeout_sec=5.0)
        assert (await client.call_async(srv.Snapshot.Request())).success is True
        await _wait_for(lambda: recorder.statistics().snapshots == 1, "the snapshot to be written")

        got = _read(out)  # while still recording: the directory is already a complete bag
        assert got["/fast"] == [t * 10 * _MS for t in range(401, 501)]
        assert got["/slow"] == [t * 100 * _MS for t in range(41, 51)]

        for k in range(501, 551):  # half a second more, then the trigger topic takes the next snapshot
            await sim.set(k * 0.01)
            fast.publish(PAYLOAD)
        trigger.publish(Empty())
        await _wait_for(lambda: recorder.statistics().snapshots == 2, "the triggered snapshot")
        recorder.stop()
    got = _read(out)
    assert got["/fast"][-50:] == [t * 10 * _MS for t in range(501, 551)]
    assert len(got["/fast"]) == 150 and len(got["/slow"]) == 10
    with BagReader(out) as reader:
        assert [f.name for f in reader.files] == ["flight_0.mcap", "flight_1.mcap"] and reader.message_count == 160


async def test_snapshot_outside_snapshot_mode_is_refused_and_has_no_service(tmp_path: Path) -> None:
    async with Runtime(handle_signals=False) as rt:
        recorder = rt.add_node(Recorder(path=str(tmp_path / "plain"), topics=["/x"]))
        assert recorder.snapshot() is False
        assert not any(name == "/recorder/snapshot" for name, _ in recorder.get_service_names_and_types())
        assert recorder.statistics().snapshots == 0
    with pytest.raises(ValueError, match=r"snapshot_mode keeps the last max_cache_size bytes in memory, so max_cache_size must be > 0, found 0"):
        Recorder(path=str(tmp_path / "nope"), topics=["/x"], snapshot_mode=True)


def test_cli_snapshot_mode_needs_a_cache_size() -> None:
    done = subprocess.run([sys.executable, "-m", "aiorobot.cli", "bag", "record", "-a", "--snapshot-mode", "--transport", "local"],
                          capture_output=True, text=True, timeout=30)
    assert done.returncode == 2
    assert done.stderr == ("aiorobot bag record: error: --snapshot-mode keeps the last --max-cache-size MB in memory: "
                           "give --max-cache-size\n")


async def test_a_failing_callback_takes_a_snapshot_with_snapshot_on_failure(tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    out = tmp_path / "crash"
    async with Runtime(handle_signals=False) as rt:
        talker = rt.add_node(Node("talker"))
        pub = talker.create_publisher(String, "/fast", 10)
        listener = rt.add_node(Node("listener"))

        def fragile(msg: String) -> None:
            if msg.data == "boom":
                raise RuntimeError("the listener broke")

        listener.create_subscription(String, "/fast", fragile, 10)
        recorder = rt.add_node(Recorder(path=str(out), topics=["/fast"], snapshot_mode=True, max_cache_size=10 * SIZE,
                                        snapshot_on_failure=True))
        await rt.settle()
        for _ in range(20):
            pub.publish(PAYLOAD)
        await rt.settle()
        assert recorder.statistics().snapshots == 0  # nothing went wrong yet
        pub.publish(String(data="boom"))
        await _wait_for(lambda: recorder.statistics().snapshots == 1, "the snapshot after the failure")
        recorder.stop()
    from rosbags.highlevel import AnyReader

    with AnyReader([out]) as reader:
        data = [reader.deserialize(raw, c.msgtype).data for c, _, raw in reader.messages()]
    assert data[-1] == "boom" and len(data) == 10  # the last max_cache_size worth, up to the failure
    assert any("taking a snapshot" in r.getMessage() for r in caplog.records)
