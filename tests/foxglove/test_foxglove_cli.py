"""The command line: ``aiorobot bag play --foxglove`` hands the playback bar to the app, and
``aiorobot foxglove`` refuses a bad asset root in one line, before starting anything."""

from __future__ import annotations

import asyncio
import re
import signal
import struct
import subprocess
import sys
from pathlib import Path

import pytest

from aiorobot.bag import BagWriter
from aiorobot.msgs import serialize
from aiorobot.msgs.std_msgs import Int32

pytest.importorskip("websockets")
from foxglove_wsclient import FoxgloveClient  # noqa: E402

T0 = 1_700_000_000 * 10**9


def test_a_missing_asset_root_is_a_usage_error(tmp_path: Path) -> None:
    proc = subprocess.run([sys.executable, "-m", "aiorobot.cli", "foxglove", "--asset-root", str(tmp_path / "nope"), "--transport", "local"],
                          capture_output=True, text=True, timeout=60)
    assert proc.returncode == 2
    assert f"expected a folder of assets, found '{tmp_path / 'nope'}' (not a directory)" in proc.stderr
    assert "Traceback" not in proc.stderr


async def test_bag_play_foxglove_is_driven_by_the_playback_bar(tmp_path: Path) -> None:
    bag = tmp_path / "count"
    with BagWriter(bag) as writer:
        writer.add_topic("/count", "std_msgs/msg/Int32")
        for i in range(10):
            writer.write("/count", T0 + i * 100_000_000, serialize(Int32(data=i)))
    proc = await asyncio.create_subprocess_exec(
        sys.executable, "-m", "aiorobot.cli", "bag", "play", str(bag), "--foxglove", "0", "--start-paused", "--transport", "local",
        stdin=asyncio.subprocess.DEVNULL, stderr=asyncio.subprocess.PIPE)
    try:
        assert proc.stderr is not None
        port = None
        async with asyncio.timeout(30):
            while port is None:
                line = (await proc.stderr.readline()).decode()
                assert line, "bag play ended before serving Foxglove"
                found = re.search(r"ws://127\.0\.0\.1:(\d+)", line)
                port = int(found.group(1)) if found else None
        async with FoxgloveClient(port) as client:
            info = await client.wait_op("serverInfo")
            assert "playbackControl" in info["capabilities"]
            rid = b"go"
            await client._ws.send(struct.pack("<BBfBQI", 0x03, 0, 10.0, 0, 0, len(rid)) + rid)
            ended = await client.until(lambda: [f for f in client.frames(0x05) if f[1] == 3])
            assert struct.unpack_from("<Q", ended[0], 2)[0] == T0 + 900_000_000
        proc.send_signal(signal.SIGINT)  # the end of the bag leaves the app in charge: Ctrl-C stops
        async with asyncio.timeout(30):
            rest = (await proc.stderr.read()).decode()
        assert await proc.wait() == 0
        assert "played 10 messages" in rest
    finally:
        if proc.returncode is None:
            proc.kill()
            await proc.wait()
