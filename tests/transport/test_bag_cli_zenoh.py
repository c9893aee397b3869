"""``aiorobot bag record`` and ``bag play`` against a graph running in another process, over zenoh."""

from __future__ import annotations

import asyncio
import os
import sys
from pathlib import Path

from aiorobot import Node, qos_profile_sensor_data
from aiorobot.bag import BagReader
from aiorobot.msgs.sensor_msgs import Imu
from aiorobot.testing import wait_for_message

from ._helpers import peer_runtime


def _zenoh_env(tmp_path: Path, port: int) -> dict[str, str]:
    conf = tmp_path / "zenoh.json5"
    conf.write_text('{ mode: "peer", connect: { endpoints: ["tcp/127.0.0.1:%d"] }, listen: { endpoints: ["tcp/127.0.0.1:0"] },'
                    ' scouting: { multicast: { enabled: false } } }' % port)
    return {**os.environ, "ZENOH_SESSION_CONFIG_URI": str(conf)}


async def test_record_from_the_cli_then_play_it_back_to_another_process(router_port: int, tmp_path: Path) -> None:
    env = _zenoh_env(tmp_path, router_port)
    graph = tmp_path / "graph.toml"
    graph.write_text('[runtime]\ntransport = "zenoh"\n[[nodes]]\nname = "imu"\nuse = "aiorobot.examples.sensor:ImuPublisher"\n')
    talker = await asyncio.create_subprocess_exec(sys.executable, "-m", "aiorobot.cli", "run", str(graph), "--duration", "60",
                                                  env=env, stdout=asyncio.subprocess.DEVNULL, stderr=asyncio.subprocess.DEVNULL)
    bag = tmp_path / "imu_bag"
    try:
        recorder = await asyncio.create_subprocess_exec(sys.executable, "-m", "aiorobot.cli", "bag", "record", "/imu", "-o", str(bag),
                                                        "--duration", "4", env=env, stdout=asyncio.subprocess.PIPE,
                                                        stderr=asyncio.subprocess.PIPE)
        _, err = await asyncio.wait_for(recorder.communicate(), 60)
        assert recorder.returncode == 0, err.decode()
    finally:
        talker.terminate()
        await talker.wait()
    with BagReader(bag) as reader:
        assert [t.name for t in reader.topics] == ["/imu"]
        recorded = reader.message_count
    assert recorded > 5
    # Play it back from the CLI into this process, over the same router.
    async with peer_runtime(router_port) as rt:
        probe = rt.add_node(Node("probe"))
        waiting = asyncio.ensure_future(wait_for_message(probe, Imu, "/imu", timeout_sec=40, qos=qos_profile_sensor_data))
        player = await asyncio.create_subprocess_exec(sys.executable, "-m", "aiorobot.cli", "bag", "play", str(bag), "--loop",
                                                      env=env, stdout=asyncio.subprocess.DEVNULL, stderr=asyncio.subprocess.PIPE)
        try:
            msg = await waiting
            assert msg.header.frame_id == "imu_link"
        finally:
            player.terminate()
            await player.wait()
