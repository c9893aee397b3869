"""examples/mecanum_serial.toml uses a per-run pty link, so two runs do not share a port."""

from __future__ import annotations

import os
from pathlib import Path

from aiorobot.launch import load_config

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "mecanum_serial.toml"


def test_the_example_link_path_is_per_process():
    from control import SerialMotorBridge, SimulatedFirmwareNode

    config = load_config(EXAMPLE)
    by_name = {n.name: n for n in config.nodes}
    link = by_name["simulated_firmware"].parameters["port_link"]
    assert link == by_name["motor_bridge"].parameters["port"] and "{pid}" in link
    firmware = SimulatedFirmwareNode(parameter_overrides={"port_link": link})
    bridge = SerialMotorBridge(parameter_overrides={"port": link})
    expected = link.replace("{pid}", str(os.getpid()))
    assert firmware.port_link == bridge.port == expected
