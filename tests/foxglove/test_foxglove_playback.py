"""Playback control: Foxglove's playback bar (play, pause, seek, speed) drives a bag Player, and
the Player's own control API (seek, set_rate, current_time_ns) behaves without a bridge too."""

from __future__ import annotations

import struct
from pathlib import Path

import pytest

from aiorobot import Node, Runtime
from aiorobot.bag import BagWriter, Player
from aiorobot.foxglove import FoxgloveBridge
from aiorobot.msgs import serialize
from aiorobot.msgs.std_msgs import Int32

pytest.importorskip("websockets")
from foxglove_wsclient import FoxgloveClient  # noqa: E402

T0 = 1_700_000_000 * 10**9
STEP = 100_000_000  # 100 ms between messages
PLAYBACK_STATE = 0x05
PLAY, PAUSE = 0, 1
PLAYING, PAUSED, ENDED = 0, 1, 3


def _bag(tmp: Path, n: int = 50) -> Path:
    path = tmp / "count"
    with BagWriter(path) as writer:
        writer.add_topic("/count", "std_msgs/msg/Int32")
        for i in range(n):
            writer.write("/count", T0 + i * STEP, serialize(Int32(data=i)))
    return path


class Counter(Node):
    def __init__(self) -> None:
        super().__init__("counter")
        self.values: list[int] = []
        self.create_subscription(Int32, "/count", lambda m: self.values.append(m.data), 100)


def _request(command: int, speed: float, request_id: str, seek_ns: int | None = None) -> bytes:
    rid = request_id.encode()
    return struct.pack("<BBfBQI", 0x03, command, speed, seek_ns is not None, seek_ns or 0, len(rid)) + rid


def _states(client: FoxgloveClient) -> list[tuple[int, int, float, bool, str]]:
    out = []
    for f in client.frames(PLAYBACK_STATE):
        status, current, speed, did_seek, n = struct.unpack_from("<BQfBI", f, 1)
        out.append((status, current, speed, bool(did_seek), f[19:19 + n].decode()))
    return out


async def _answer(client: FoxgloveClient, request_id: str) -> tuple[int, int, float, bool, str]:
    return await client.until(lambda: next((s for s in _states(client) if s[4] == request_id), None))


async def test_play_pause_seek_and_speed_from_the_playback_bar(tmp_path: Path) -> None:
    async with Runtime(handle_signals=False) as rt:
        counter = rt.add_node(Counter())
        player = rt.add_node(Player(path=str(_bag(tmp_path)), start_paused=True))
        bridge = rt.add_node(FoxgloveBridge(port=0, player=player))
        async with FoxgloveClient(bridge.bound_port) as client:
            info = await client.wait_op("serverInfo")
            assert "playbackControl" in info["capabilities"]
            await client._ws.send(_request(PLAY, 4.0, "play"))
            status, _, speed, _, _ = await _answer(client, "play")
            assert (status, speed) == (PLAYING, 4.0)
            await client.until(lambda: len(counter.values) >= 3)
            await client._ws.send(_request(PAUSE, 4.0, "pause"))
            assert (await _answer(client, "pause"))[0] == PAUSED
            assert player.statistics().paused
            await client._ws.send(_request(PAUSE, 4.0, "seek", seek_ns=T0 + 40 * STEP))
            status, current, _, did_seek, _ = await _answer(client, "seek")
            assert (status, current, did_seek) == (PAUSED, T0 + 40 * STEP, True)
            await client._ws.send(_request(PLAY, 8.0, "again"))
            assert (await _answer(client, "again"))[2] == 8.0
            await client.until(lambda: any(s[0] == ENDED for s in _states(client)))
        seek = counter.values.index(40)
        assert 3 <= seek < 40 and counter.values[:seek] == list(range(seek))
        assert counter.values[seek:] == list(range(40, 50))  # on from the seek point, nothing skipped
        assert player.rate == 8.0


async def test_player_seeks_while_paused_and_after_the_end_and_clamps_to_the_bag(tmp_path: Path) -> None:
    async with Runtime(handle_signals=False) as rt:
        counter = rt.add_node(Counter())
        player = rt.add_node(Player(path=str(_bag(tmp_path, 20)), start_paused=True, rate=20.0))
        assert player.current_time_ns == T0
        player.seek(T0 + 15 * STEP)
        assert player.current_time_ns == T0 + 15 * STEP
        player.resume()
        assert await player.wait_for_completion(timeout_sec=20)
        assert counter.values == list(range(15, 20))
        player.pause()
        player.seek(T0 + 17 * STEP)  # after the end: plays again from there once resumed
        assert not player.done and player.current_time_ns == T0 + 17 * STEP
        player.resume()
        assert await player.wait_for_completion(timeout_sec=20)
        assert counter.values == [*range(15, 20), 17, 18, 19]
        player.seek(T0 - STEP)  # clamped to the bag's start (and playing again from there at once)
        assert T0 <= player.current_time_ns < T0 + STEP
