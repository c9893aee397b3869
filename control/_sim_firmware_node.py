"""``SimulatedFirmwareNode``: a :class:`SimulatedFirmware` on a pty, as a node for ``aiorobot run``."""

from __future__ import annotations

import asyncio
import os
from typing import Any

from aiorobot import Node

from ._sim_firmware import PtyFirmware, SimulatedFirmware

__all__ = ["SimulatedFirmwareNode"]


class SimulatedFirmwareNode(Node):
    """Serves a simulated motor firmware on a pseudo-terminal linked at ``port_link``.

    Point a :class:`SerialMotorBridge`'s ``port`` parameter at the same path and the
    whole chain runs without hardware. The pty exists from ``on_start`` until shutdown.
    """

    def __init__(self, **kw: Any) -> None:
        super().__init__("simulated_firmware", **kw)
        p = self.declare_parameter
        self.port_link = p(
            "port_link", "/tmp/aiorobot-sim-motors", description="symlink to the pty slave; {pid} is this process's id"
        ).value.replace("{pid}", str(os.getpid()))
        firmware = SimulatedFirmware(
            wheel_count=p("wheel_count", 4, description="number of motors", range=(1, 8)).value,
            ticks_per_revolution=p("ticks_per_revolution", 4096, description="encoder resolution", range=(1, 1_000_000)).value,
            motor_time_constant_sec=p("motor_time_constant_sec", 0.05, description="first-order motor lag", range=(1e-4, 10.0)).value,
            max_wheel_speed_rad_s=p("max_wheel_speed", 40.0, description="motor speed limit, rad/s", range=(0.1, 1e4)).value,
            host_timeout_sec=p("host_timeout_sec", 0.5, description="hold motors without host heartbeat", range=(0.01, 60.0)).value,
            ticks_period_sec=1.0 / p("ticks_rate_hz", 50.0, description="encoder report rate", range=(1.0, 1000.0)).value,
        )
        self.linger_sec = p(
            "linger_sec", 0.1, description="keep serving this long during shutdown", range=(0.0, 5.0)
        ).value
        rate_hz = p("rate_hz", 200.0, description="simulation step rate", range=(10.0, 2000.0)).value
        self.pty = PtyFirmware(firmware, link_path=self.port_link, period_sec=1.0 / rate_hz)
        self.create_timer(1.0 / rate_hz, self.on_tick)

    @property
    def firmware(self) -> SimulatedFirmware:
        return self.pty.firmware

    async def on_start(self) -> None:
        self.pty.open()
        self.pty.attach()
        self.get_logger().info(f"simulated firmware on {self.pty.slave_path} (linked at {self.port_link})")

    def on_tick(self) -> None:
        if self.pty.is_open:
            self.pty.pump()

    def summary(self) -> str:
        fw = self.firmware
        stats = fw.decoder.statistics()
        return (
            f"{self.get_name()}: {fw.commands_received} wheel commands, {stats.frames_ok} frames from the host "
            f"({stats.bad_frames} bad), final status {fw.status.name or int(fw.status)}"
        )

    async def on_shutdown(self) -> None:
        # Linger: keep reading for a moment so what other nodes send from their own shutdown
        # hooks (a bridge's last zero command) still reaches the firmware, then unplug.
        loop = asyncio.get_running_loop()
        deadline = loop.time() + self.linger_sec
        while loop.time() < deadline:
            await asyncio.sleep(0.01)
            self.pty.drain()
            self.pty.pump()
        self.pty.close_pty()
