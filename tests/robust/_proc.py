"""Helpers for the robustness tests: a node module to run under ``aiorobot run`` and a pty firmware thread."""

from __future__ import annotations

import asyncio
import os
import signal
import subprocess
import sys
import textwrap
import threading
import time
from pathlib import Path

from control import PtyFirmware
from control._messages import SetWheelVelocities

AIOROBOT = str(Path(sys.executable).with_name("aiorobot"))

NODES = textwrap.dedent(
    '''
    import time

    import numpy as np

    from aiorobot import Node
    from aiorobot.msgs.sensor_msgs import JointState


    class Commander(Node):
        """Drives the wheels, then blocks where it is told to (a blocking serial read, say)."""

        def __init__(self, **kw):
            super().__init__("commander", **kw)
            self.block_in = self.declare_parameter("block_in", "callback").value
            self.pub = self.create_publisher(JointState, "/wheel_commands", 10)
            self.ticks = 0
            self.create_timer(0.05, self.tick)

        def tick(self):
            self.ticks += 1
            msg = JointState()
            msg.velocity = np.full(4, 2.0)
            self.pub.publish(msg)
            if self.ticks == 10:
                print("READY", flush=True)
                if self.block_in == "callback":
                    time.sleep(60)

        async def on_shutdown(self):
            if self.block_in == "on_shutdown":
                time.sleep(60)


    class SlowConstructor(Node):
        def __init__(self, **kw):
            super().__init__("slow", **kw)
            print("READY", flush=True)
            time.sleep(60)
    '''
)


def write_graph(folder: Path, port: str, *, executor: str, block_in: str, use: str = "Commander",
                shutdown_timeout: float = 1.0) -> Path:
    (folder / "blockers.py").write_text(NODES)
    config = folder / "graph.toml"
    config.write_text(
        textwrap.dedent(
            f'''
            [runtime]
            shutdown_timeout = {shutdown_timeout}

            [[nodes]]
            use = "aiorobot.control:SerialMotorBridge"
            parameters = {{ port = "{port}", reconnect_period_sec = 0.05 }}

            [[nodes]]
            use = "blockers:{use}"
            executor = "{executor}"
            parameters = {{ block_in = "{block_in}" }}
            '''
        )
    )
    return config


class FirmwareThread:
    """A :class:`PtyFirmware` served by its own event loop in a thread (the robot's side)."""

    def __init__(self, link_path: str) -> None:
        self.pty = PtyFirmware(link_path=link_path)
        self._started = threading.Event()
        self._loop: asyncio.AbstractEventLoop | None = None
        self._stop: asyncio.Event | None = None
        self._thread = threading.Thread(target=lambda: asyncio.run(self._main()), daemon=True)

    async def _main(self) -> None:
        self._loop = asyncio.get_running_loop()
        self._stop = asyncio.Event()
        async with self.pty:
            self._started.set()
            await self._stop.wait()
            self.pty.drain()

    def __enter__(self) -> FirmwareThread:
        self._thread.start()
        assert self._started.wait(10)
        return self

    def __exit__(self, *exc: object) -> None:
        assert self._loop is not None and self._stop is not None
        self._loop.call_soon_threadsafe(self._stop.set)
        self._thread.join(10)

    def wheel_commands(self) -> list[tuple[float, ...]]:
        return [m.velocities_rad_s for m in list(self.pty.firmware.received) if isinstance(m, SetWheelVelocities)]


def start(args: list[str], cwd: Path) -> subprocess.Popen[str]:
    env = dict(os.environ, PYTHONUNBUFFERED="1", COLUMNS="100")
    return subprocess.Popen(
        [AIOROBOT, *args], cwd=cwd, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
    )


def wait_for_line(proc: subprocess.Popen[str], marker: str, timeout_sec: float = 30.0) -> None:
    """Read stdout until ``marker`` (the child prints it when it is about to block)."""
    assert proc.stdout is not None
    deadline = time.monotonic() + timeout_sec
    while time.monotonic() < deadline:
        line = proc.stdout.readline()
        if marker in line:
            return
        if not line and proc.poll() is not None:
            raise AssertionError(f"exited {proc.returncode} before {marker!r}: {proc.stderr.read() if proc.stderr else ''}")
    raise AssertionError(f"no {marker!r} within {timeout_sec} s")


def interrupt(proc: subprocess.Popen[str], sig: int = signal.SIGINT) -> None:
    proc.send_signal(sig)
