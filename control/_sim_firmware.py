"""A simulated motor-controller firmware speaking the serial protocol.

:class:`SimulatedFirmware` is the pure core: bytes in, bytes out, time passed in
explicitly. :class:`PtyFirmware` runs it on a real pseudo-terminal so the bridge
opens the slave path with pyserial exactly as it would open ``/dev/ttyUSB0``.
"""

from __future__ import annotations

import asyncio
import contextlib
import errno
import math
import os
import time
import tty
from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ._checks import check_positive
from ._decoder import StreamDecoder
from ._messages import (
    MAX_WHEELS,
    PROTOCOL_VERSION,
    ClearEmergencyStop,
    EmergencyStop,
    EncoderTicks,
    FirmwareHeartbeat,
    FirmwareStatus,
    HostHeartbeat,
    Message,
    ResetEncoders,
    SetWheelVelocities,
    VersionRequest,
    VersionResponse,
    encode_message,
)

__all__ = ["SimulatedFirmware", "PtyFirmware"]


class SimulatedFirmware:
    """Firmware behaviour: motors, encoders, heartbeats, e-stop, in pure Python.

    - Each wheel follows a first-order motor model, ``d(omega)/dt = (target - omega) / tau``,
      integrated exactly between calls; the wheel angle integrates the speed.
    - Encoder ticks (``floor(angle * ticks_per_revolution / 2 pi)``, wrapping int32) are sent
      every ``ticks_period_sec`` with the firmware's microsecond timestamp, a heartbeat every
      ``heartbeat_period_sec``.
    - Like real firmware it starts with the motors held (``HOST_TIMEOUT``) until the first host
      heartbeat, and holds them again whenever no host heartbeat came for ``host_timeout_sec``;
      velocity commands are ignored while held. An ``EmergencyStop`` latches until
      ``ClearEmergencyStop``. After either, motors stay at zero until the next command.

    Parameters
    ----------
    wheel_count : int
        Number of motors, 1..8.
    ticks_per_revolution : int
        Encoder resolution.
    motor_time_constant_sec : float
        First-order time constant ``tau`` of every motor, > 0.
    max_wheel_speed_rad_s : float
        Commands are clipped to this speed.
    """

    def __init__(
        self,
        *,
        wheel_count: int = 4,
        ticks_per_revolution: int = 4096,
        motor_time_constant_sec: float = 0.05,
        max_wheel_speed_rad_s: float = 40.0,
        host_timeout_sec: float = 0.5,
        ticks_period_sec: float = 0.02,
        heartbeat_period_sec: float = 0.1,
        name: str = "aiorobot-sim",
        version: tuple[int, int, int] = (0, 1, 0),
    ) -> None:
        if not 1 <= int(wheel_count) <= MAX_WHEELS:
            raise ValueError(f"wheel_count must be 1..{MAX_WHEELS}, got {wheel_count!r}")
        self.wheel_count = int(wheel_count)
        self.ticks_per_revolution = int(check_positive("ticks_per_revolution", ticks_per_revolution))
        self.motor_time_constant_sec = check_positive("motor_time_constant_sec", motor_time_constant_sec)
        self.max_wheel_speed_rad_s = check_positive("max_wheel_speed_rad_s", max_wheel_speed_rad_s)
        self.host_timeout_sec = check_positive("host_timeout_sec", host_timeout_sec)
        self.ticks_period_sec = check_positive("ticks_period_sec", ticks_period_sec)
        self.heartbeat_period_sec = check_positive("heartbeat_period_sec", heartbeat_period_sec)
        self.name = name
        self.version = version
        self.decoder = StreamDecoder()
        self.target_rad_s: NDArray[np.float64] = np.zeros(self.wheel_count)
        self.speed_rad_s: NDArray[np.float64] = np.zeros(self.wheel_count)
        self.angle_rad: NDArray[np.float64] = np.zeros(self.wheel_count)
        self.estop = False
        self.host_timeout = True
        self.commands_received = 0
        self.received: list[Message] = []  # the last few messages, for inspection
        self._seq = 0
        self._t0: float | None = None
        self._now: float | None = None
        self._last_host_heartbeat: float | None = None
        self._next_ticks = 0.0
        self._next_heartbeat = 0.0
        self._pending = bytearray()

    def __repr__(self) -> str:
        return (
            f"<SimulatedFirmware wheels={self.wheel_count} status={self.status!r} "
            f"speed={np.round(self.speed_rad_s, 3).tolist()}>"
        )

    @property
    def status(self) -> FirmwareStatus:
        flags = FirmwareStatus.OK
        if self.estop:
            flags |= FirmwareStatus.ESTOP
        if self.host_timeout:
            flags |= FirmwareStatus.HOST_TIMEOUT
        return flags

    @property
    def ticks(self) -> NDArray[np.int64]:
        """Current encoder counters (wrapped to int32)."""
        raw = np.floor(self.angle_rad * self.ticks_per_revolution / (2.0 * math.pi)).astype(np.int64)
        return (raw + 2**31) % 2**32 - 2**31

    def _start(self, now_sec: float) -> None:
        if self._t0 is None:
            self._t0 = self._now = now_sec
            self._next_ticks = now_sec
            self._next_heartbeat = now_sec

    def _send(self, message: Message) -> None:
        self._pending += encode_message(message, self._seq)
        self._seq = (self._seq + 1) & 0xFF

    def _hold(self) -> None:
        self.target_rad_s[:] = 0.0

    def receive(self, data: bytes, now_sec: float) -> None:
        """Feed bytes from the host, received at ``now_sec``; motors are integrated up to then first."""
        self._start(now_sec)
        self._integrate(now_sec)
        for message in self.decoder.feed(data):
            self.received = (self.received + [message])[-32:]
            self._handle(message, now_sec)

    def _handle(self, message: Message, now_sec: float) -> None:
        if isinstance(message, HostHeartbeat):
            self._last_host_heartbeat = now_sec
            self.host_timeout = False
        elif isinstance(message, SetWheelVelocities):
            self.commands_received += 1
            if self.estop or self.host_timeout:
                return
            values = np.asarray(message.velocities_rad_s[: self.wheel_count], dtype=np.float64)
            target = np.zeros(self.wheel_count)
            target[: len(values)] = np.nan_to_num(values)
            self.target_rad_s = np.clip(target, -self.max_wheel_speed_rad_s, self.max_wheel_speed_rad_s)
        elif isinstance(message, EmergencyStop):
            self.estop = True
            self._hold()
        elif isinstance(message, ClearEmergencyStop):
            self.estop = False
            self._hold()
        elif isinstance(message, ResetEncoders):
            self.angle_rad[:] = 0.0
        elif isinstance(message, VersionRequest):
            major, minor, patch = self.version
            self._send(
                VersionResponse(
                    PROTOCOL_VERSION, major, minor, patch, self.wheel_count, self.ticks_per_revolution, self.name
                )
            )

    def _integrate(self, now_sec: float) -> None:
        assert self._now is not None
        dt = now_sec - self._now
        if dt <= 0.0:
            return
        decay = math.exp(-dt / self.motor_time_constant_sec)
        offset = self.speed_rad_s - self.target_rad_s
        self.angle_rad += self.target_rad_s * dt + offset * self.motor_time_constant_sec * (1.0 - decay)
        self.speed_rad_s = self.target_rad_s + offset * decay
        self._now = now_sec

    def advance(self, now_sec: float) -> bytes:
        """Integrate the motors to ``now_sec`` and return the bytes the firmware sends by then."""
        self._start(now_sec)
        self._integrate(now_sec)
        if (
            not self.host_timeout
            and self._last_host_heartbeat is not None
            and now_sec - self._last_host_heartbeat > self.host_timeout_sec
        ):
            self.host_timeout = True
            self._hold()
        assert self._t0 is not None
        if now_sec >= self._next_ticks:
            stamp_us = int(round((now_sec - self._t0) * 1e6))
            self._send(EncoderTicks(stamp_us, tuple(int(t) for t in self.ticks)))
            self._next_ticks = max(self._next_ticks + self.ticks_period_sec, now_sec)
        if now_sec >= self._next_heartbeat:
            self._send(FirmwareHeartbeat(int((now_sec - self._t0) * 1000.0), self.status))
            self._next_heartbeat = max(self._next_heartbeat + self.heartbeat_period_sec, now_sec)
        out = bytes(self._pending)
        self._pending.clear()
        return out

    def service(self, port: Any, now_sec: float) -> None:
        """One round on a pyserial port (e.g. ``serial.serial_for_url("loop://")``): read, integrate, write."""
        waiting = port.in_waiting
        if waiting:
            self.receive(port.read(waiting), now_sec)
        out = self.advance(now_sec)
        if out:
            port.write(out)


class PtyFirmware:
    """Runs a :class:`SimulatedFirmware` on a pseudo-terminal inside the running event loop.

    ``async with PtyFirmware() as fw:`` then open ``fw.port_path`` with pyserial. With
    ``link_path`` a symlink to the slave is made there (like ``socat``'s ``link=``), so a
    test can close one firmware and start another under the same path to make the port
    disappear and come back.

    Parameters
    ----------
    firmware : SimulatedFirmware, optional
        The behaviour; a 4-wheel default if omitted.
    link_path : str, optional
        Where to put a stable symlink to the slave device.
    period_sec : float
        How often the motors are integrated and output flushed.
    clock : callable, optional
        Seconds, monotonic; ``time.monotonic`` by default.
    """

    def __init__(
        self,
        firmware: SimulatedFirmware | None = None,
        *,
        link_path: str | None = None,
        period_sec: float = 0.005,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.firmware = firmware if firmware is not None else SimulatedFirmware()
        self.link_path = link_path
        self.period_sec = check_positive("period_sec", period_sec)
        self._clock = clock
        self._master: int | None = None
        self._slave: int | None = None
        self._task: asyncio.Task[None] | None = None
        self._loop: asyncio.AbstractEventLoop | None = None
        self.slave_path = ""
        self.bytes_dropped = 0

    def __repr__(self) -> str:
        state = "running" if self._task is not None else "open" if self._master is not None else "closed"
        return f"<PtyFirmware {self.port_path or '-'} {state} {self.firmware!r}>"

    @property
    def port_path(self) -> str:
        """The path to open with pyserial: the symlink if one was asked for, else the slave device."""
        return self.link_path or self.slave_path

    @property
    def is_open(self) -> bool:
        return self._master is not None

    def open(self) -> None:
        """Create the pty (and the link) now, without serving yet: the port exists from here on."""
        if self._master is not None:
            raise RuntimeError(f"{self!r} is already open")
        if self.link_path and os.path.lexists(self.link_path) and not os.path.islink(self.link_path):
            raise FileExistsError(
                f"link_path {self.link_path!r} exists and is not a symlink; PtyFirmware only replaces "
                "its own links, so pick a free path such as /tmp/aiorobot-sim-motors"
            )
        master, slave = os.openpty()
        tty.setraw(slave)
        os.set_blocking(master, False)
        self._master, self._slave = master, slave
        self.slave_path = os.ttyname(slave)
        if self.link_path:
            with contextlib.suppress(FileNotFoundError):
                os.unlink(self.link_path)
            os.symlink(self.slave_path, self.link_path)

    def attach(self, loop: asyncio.AbstractEventLoop | None = None) -> None:
        """Start receiving: watch the master side on ``loop`` (default: the running loop)."""
        if self._master is None:
            self.open()
        assert self._master is not None
        if self._loop is None:
            self._loop = loop if loop is not None else asyncio.get_running_loop()
            self._loop.add_reader(self._master, self._on_readable)

    def pump(self) -> None:
        """Integrate the firmware to now and write what it sends; call every ``period_sec``."""
        out = self.firmware.advance(self._clock())
        if out and self._master is not None:
            try:
                written = os.write(self._master, out)
                self.bytes_dropped += len(out) - written
            except OSError:
                self.bytes_dropped += len(out)  # nobody reading: a UART drops bytes too

    async def start(self) -> None:
        """Open the pty if needed, then serve it from a task on the running loop."""
        if self._task is not None:
            raise RuntimeError(f"{self!r} is already running")
        self.attach()
        self._task = asyncio.create_task(self._run(), name=f"pty-firmware {self.port_path}")

    def close_pty(self) -> None:
        """Close the pty (the device disappears) and remove the link; the serving task is not touched."""
        if self._master is not None:
            if self._loop is not None:
                self._loop.remove_reader(self._master)
            os.close(self._master)
            self._master = None
        self._loop = None
        if self._slave is not None:
            os.close(self._slave)
            self._slave = None
        if self.link_path:
            with contextlib.suppress(OSError):
                if os.path.islink(self.link_path) and os.readlink(self.link_path) == self.slave_path:
                    os.unlink(self.link_path)

    async def close(self) -> None:
        """Stop serving and close the pty."""
        if self._task is not None:
            self._task.cancel()
            with contextlib.suppress(asyncio.CancelledError):
                await self._task
            self._task = None
        self.close_pty()

    async def __aenter__(self) -> PtyFirmware:
        await self.start()
        return self

    async def __aexit__(self, *exc: object) -> None:
        await self.close()

    def _on_readable(self) -> bool:
        """Read one chunk from the master side into the firmware; False when nothing was there."""
        if self._master is None:
            return False
        try:
            data = os.read(self._master, 4096)
        except BlockingIOError:
            return False
        except OSError as exc:
            if exc.errno == errno.EIO:  # no slave open right now
                return False
            raise
        self.firmware.receive(data, self._clock())
        return bool(data)

    def drain(self) -> None:
        """Take in everything the host has written so far (before closing, say)."""
        while self._on_readable():
            pass

    async def _run(self) -> None:
        while True:
            self.pump()
            await asyncio.sleep(self.period_sec)
