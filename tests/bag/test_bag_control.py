"""rosbag2's control services (rosbag2_interfaces) on Player and Recorder, each called through a service client."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from aiorobot import Node, Runtime
from aiorobot.bag import BagReader, BagWriter, Player, Recorder
from aiorobot.msgs import deserialize, rosbag2_interfaces as srv, serialize
from aiorobot.msgs.builtin_interfaces import Time as TimeMsg
from aiorobot.msgs.std_msgs import String

_SEC = 1_000_000_000


def _bag(path: Path, n: int = 10) -> Path:
    """``n`` messages ten seconds apart: at rate 1 nothing becomes due while a test runs."""
    with BagWriter(path) as writer:
        writer.add_topic("/chatter", "std_msgs/msg/String")
        for i in range(n):
            writer.write("/chatter", (100 + 10 * i) * _SEC, serialize(String(data=f"m{i}")))
    return path


async def _call(rt: Runtime, node: Node, kind: Any, name: str, **fields: Any) -> Any:
    client = node.create_client(kind, name)
    assert await client.wait_for_service(timeout_sec=5.0), name
    response = await client.call_async(kind.Request(**fields))
    await rt.settle()
    node.destroy_client(client)
    return response


async def test_player_services_pause_rate_step_burst_seek_and_stop(tmp_path: Path) -> None:
    bag = _bag(tmp_path / "ten")
    async with Runtime(handle_signals=False) as rt:
        probe = rt.add_node(Node("probe"))
        got: list[str] = []
        probe.create_subscription(String, "/chatter", lambda m: got.append(m.data), 50)
        player = rt.add_node(Player(path=str(bag), start_paused=True))
        await rt.settle()

        assert (await _call(rt, probe, srv.IsPaused, "/player/is_paused")).paused is True
        assert (await _call(rt, probe, srv.GetRate, "/player/get_rate")).rate == 1.0
        assert (await _call(rt, probe, srv.SetRate, "/player/set_rate", rate=2.5)).success is True
        assert (await _call(rt, probe, srv.GetRate, "/player/get_rate")).rate == 2.5
        assert (await _call(rt, probe, srv.SetRate, "/player/set_rate", rate=0.0)).success is False
        assert player.get_rate() == 2.5

        assert (await _call(rt, probe, srv.PlayNext, "/player/play_next")).success is True
        assert got == ["m0"]
        assert (await _call(rt, probe, srv.Burst, "/player/burst", num_messages=3)).actually_burst == 3
        assert got == ["m0", "m1", "m2", "m3"]

        assert (await _call(rt, probe, srv.Seek, "/player/seek", time=TimeMsg(sec=170))).success is True
        await _call(rt, probe, srv.PlayNext, "/player/play_next")
        assert got[-1] == "m7"
        await _call(rt, probe, srv.Seek, "/player/seek", time=TimeMsg(sec=1))  # before the bag: its start
        await _call(rt, probe, srv.PlayNext, "/player/play_next")
        assert got[-1] == "m0"

        await _call(rt, probe, srv.TogglePaused, "/player/toggle_paused")
        assert (await _call(rt, probe, srv.IsPaused, "/player/is_paused")).paused is False
        # as rosbag2: stepping only while paused
        assert (await _call(rt, probe, srv.PlayNext, "/player/play_next")).success is False
        assert (await _call(rt, probe, srv.Burst, "/player/burst", num_messages=2)).actually_burst == 0
        await _call(rt, probe, srv.Pause, "/player/pause")
        assert player.is_paused()
        await _call(rt, probe, srv.Resume, "/player/resume")
        assert not player.is_paused()

        await _call(rt, probe, srv.Stop, "/player/stop")
        assert await player.wait_for_completion(timeout_sec=5.0)
        assert got == ["m0", "m1", "m2", "m3", "m7", "m0"]  # nothing played on its own: the next was 10 s away
        assert player.statistics().published == 6


async def test_burst_of_zero_plays_the_rest_and_play_next_at_the_end_is_false(tmp_path: Path) -> None:
    bag = _bag(tmp_path / "five", n=5)
    async with Runtime(handle_signals=False) as rt:
        probe = rt.add_node(Node("probe"))
        got: list[str] = []
        probe.create_subscription(String, "/chatter", lambda m: got.append(m.data), 50)
        rt.add_node(Player(path=str(bag), start_paused=True))
        await rt.settle()
        assert (await _call(rt, probe, srv.Burst, "/player/burst", num_messages=0)).actually_burst == 5
        assert (await _call(rt, probe, srv.PlayNext, "/player/play_next")).success is False
        assert got == [f"m{i}" for i in range(5)]


async def test_recorder_services_pause_resume_and_split(tmp_path: Path) -> None:
    from rosbags.highlevel import AnyReader

    out = tmp_path / "rec"
    async with Runtime(handle_signals=False) as rt:
        talker = rt.add_node(Node("talker"))
        pub = talker.create_publisher(String, "/chatter", 10)
        recorder = rt.add_node(Recorder(path=str(out), topics=["/chatter"]))
        probe = rt.add_node(Node("probe"))
        await rt.settle()
        pub.publish(String(data="before"))
        await _call(rt, probe, srv.Pause, "/recorder/pause")
        assert (await _call(rt, probe, srv.IsPaused, "/recorder/is_paused")).paused is True
        pub.publish(String(data="while paused"))
        await _call(rt, probe, srv.Resume, "/recorder/resume")
        assert (await _call(rt, probe, srv.IsPaused, "/recorder/is_paused")).paused is False
        pub.publish(String(data="after"))
        await _call(rt, probe, srv.SplitBagfile, "/recorder/split_bagfile")
        pub.publish(String(data="second file"))
        await rt.settle()
        recorder.stop()
    assert sorted(p.name for p in out.glob("*.mcap")) == ["rec_0.mcap", "rec_1.mcap"]
    with AnyReader([out]) as reader:
        assert [reader.deserialize(raw, c.msgtype).data for c, _, raw in reader.messages()] == ["before", "after", "second file"]
    with BagReader(out) as reader:
        assert [deserialize(d, String).data for _, _, d in reader.messages()] == ["before", "after", "second file"]
        assert reader.message_count == 3


async def test_seek_and_set_rate_while_playing_take_effect_where_playback_is(tmp_path: Path) -> None:
    import asyncio

    bag = _bag(tmp_path / "ten")
    async with Runtime(handle_signals=False) as rt:
        probe = rt.add_node(Node("probe"))
        got: list[str] = []
        arrived = asyncio.Event()

        def on_message(msg: Any) -> None:
            got.append(msg.data)
            arrived.set()

        probe.create_subscription(String, "/chatter", on_message, 50)
        rt.add_node(Player(path=str(bag)))

        taken = 0

        async def next_message() -> str:
            nonlocal taken
            while len(got) <= taken:  # generous bound: each one is due at once
                await asyncio.wait_for(arrived.wait(), 10.0)
                arrived.clear()
            taken += 1
            return got[taken - 1]

        assert await next_message() == "m0"  # the first message plays at once; the next is 10 s away
        await _call(rt, probe, srv.Seek, "/player/seek", time=TimeMsg(sec=170))
        assert await next_message() == "m7"  # due at once: playback goes on from the seek
        await _call(rt, probe, srv.SetRate, "/player/set_rate", rate=10_000.0)
        assert await next_message() == "m8"  # 10 s of bag at 10000x: 1 ms
        assert await next_message() == "m9"
        assert got == ["m0", "m7", "m8", "m9"]
