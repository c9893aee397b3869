"""``[runtime] transport = "zenoh"`` and ``zenoh_config`` in a graph file: `aiorobot run` joins other processes."""

from __future__ import annotations

import asyncio
import sys
from pathlib import Path

from aiorobot import Node, qos_profile_sensor_data
from aiorobot.msgs.sensor_msgs import Imu
from aiorobot.testing import wait_for_message

from ._helpers import peer_runtime


async def test_a_graph_file_on_zenoh_reaches_another_process(router_port: int, tmp_path: Path) -> None:
    zconf = tmp_path / "zenoh.json5"
    zconf.write_text(
        '{ mode: "peer", connect: { endpoints: ["tcp/127.0.0.1:%d"] }, listen: { endpoints: ["tcp/127.0.0.1:0"] },'
        ' scouting: { multicast: { enabled: false } } }' % router_port
    )
    graph = tmp_path / "graph.toml"
    graph.write_text(
        '[runtime]\ntransport = "zenoh"\nzenoh_config = "zenoh.json5"\n'
        '[[nodes]]\nname = "imu"\nuse = "aiorobot.examples.sensor:ImuPublisher"\n'
    )
    child = await asyncio.create_subprocess_exec(sys.executable, "-m", "aiorobot.cli", "run", str(graph), "--duration", "30",
                                                 stdout=asyncio.subprocess.DEVNULL, stderr=asyncio.subprocess.PIPE)
    try:
        async with peer_runtime(router_port) as rt:
            probe = rt.add_node(Node("probe"))
            msg = await wait_for_message(probe, Imu, "/imu", timeout_sec=25, qos=qos_profile_sensor_data)
            assert msg.header.frame_id
    finally:
        child.terminate()
        await child.wait()


def test_iceoryx2_topics_in_a_graph_file_reach_the_zenoh_transport(tmp_path: Path) -> None:
    from aiorobot.launch import load_config, runtime_options

    graph = tmp_path / "graph.toml"
    graph.write_text(
        '[runtime]\ntransport = "zenoh"\niceoryx2_topics = ["*", "/camera/depth"]\n'
        '[[nodes]]\nname = "imu"\nuse = "aiorobot.examples.sensor:ImuPublisher"\n'
    )
    transport = runtime_options(load_config(graph))["transport"]
    assert transport.iceoryx2_topics == {"*", "/camera/depth"}
    graph.write_text('[runtime]\ntransport = "zenoh"\n[[nodes]]\nname = "imu"\nuse = "aiorobot.examples.sensor:ImuPublisher"\n')
    assert runtime_options(load_config(graph))["transport"] == "zenoh"  # (the environment's, when the file says nothing)
