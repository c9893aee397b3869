"""``SerialMotorBridge``: wheel commands to a motor firmware over serial, encoder feedback to ``/joint_states``."""

from __future__ import annotations

import math
import os
import time
from typing import Any

import numpy as np
from numpy.typing import NDArray

from aiorobot import Node, Time
from aiorobot.lowlevel import add_emergency_stop, remove_emergency_stop

from ._framing import FrameError
from ._messages import (
    ClearEmergencyStop,
    EmergencyStop,
    EncoderTicks,
    EstopReason,
    FirmwareHeartbeat,
    FirmwareStatus,
    HostHeartbeat,
    Message,
    SetWheelVelocities,
    VersionRequest,
    VersionResponse,
    encode_message,
)
from ._odometry import tick_delta
from ._serial_link import SerialLink

__all__ = ["SerialMotorBridge"]

#: Largest gap tolerated between host time and a mapped firmware timestamp before re-anchoring.
_MAX_CLOCK_SKEW_NS = 100_000_000

_DEFAULT_JOINTS = [
    "front_left_wheel_joint",
    "front_right_wheel_joint",
    "rear_left_wheel_joint",
    "rear_right_wheel_joint",
]


class SerialMotorBridge(Node):
    """Talks the motor protocol (``docs/serial-protocol.md``) to a firmware on a serial port.

    - ``/wheel_commands`` (sensor_msgs/JointState, ``velocity`` in rad/s, matched by
      ``name`` to ``joint_names``, or by position when unnamed) -> SET_WHEEL_VELOCITIES.
    - ENCODER_TICKS -> ``/joint_states`` (position: accumulated wheel angle in rad,
      continuous across reconnects; velocity: from tick and firmware-time differences).
    - HOST_HEARTBEAT every ``heartbeat_period_sec``; when no FIRMWARE_HEARTBEAT came for
      ``firmware_timeout_sec`` it sends EMERGENCY_STOP and logs an error, and clears that
      e-stop when the heartbeat returns.
    - ``/estop`` (std_msgs/Bool): true -> EMERGENCY_STOP, false -> CLEAR_EMERGENCY_STOP.
    - The port is reopened every ``reconnect_period_sec`` while it is missing. Bad frames are
      counted by kind (``statistics()``) and logged, throttled.
    - Reads and writes are non-blocking: the loop watches the port's descriptor.
    - Link timeouts (heartbeat, reconnect) run on the monotonic wall clock, not on
      ``/clock``: the hardware lives in real time even when the graph uses sim time.
    """

    def __init__(self, **kw: Any) -> None:
        super().__init__("serial_motor_bridge", **kw)
        p = self.declare_parameter
        self.port = p(
            "port", "/dev/ttyUSB0", description="serial device path or pyserial URL; {pid} is this process's id"
        ).value.replace("{pid}", str(os.getpid()))
        self.baud_rate = p("baud_rate", 115200, description="line speed", range=(1200, 12_000_000)).value
        self.joint_names = [str(n) for n in p("joint_names", list(_DEFAULT_JOINTS), description="wheel joints, firmware order").value]
        self.heartbeat_period_sec = p("heartbeat_period_sec", 0.1, description="host heartbeat period", range=(0.005, 10.0)).value
        self.firmware_timeout_sec = p(
            "firmware_timeout_sec", 0.5, description="e-stop when no firmware heartbeat for this long", range=(0.01, 60.0)
        ).value
        self.reconnect_period_sec = p("reconnect_period_sec", 1.0, description="retry period for a missing port", range=(0.01, 60.0)).value
        self.ticks_per_revolution = float(
            p("ticks_per_revolution", 0.0, description="encoder ticks per wheel turn; 0 = ask the firmware", range=(0.0, 1e9)).value
        )
        self.link = SerialLink(
            self.port,
            self.baud_rate,
            on_message=self._on_message,
            on_frame_error=self._on_frame_error,
            on_disconnect=self._on_disconnect,
        )
        self.firmware_version: VersionResponse | None = None
        self.firmware_status = FirmwareStatus.HOST_TIMEOUT
        self.firmware_alive = False
        self.estop_active = False  # an e-stop this bridge sent and has not cleared
        self._estop_by_watchdog = False
        self.wheel_positions_rad: NDArray[np.float64] = np.zeros(len(self.joint_names))
        self.wheel_velocities_rad_s: NDArray[np.float64] = np.zeros(len(self.joint_names))
        self._last_ticks: NDArray[np.int64] | None = None
        self._last_tick_us = 0
        self._last_firmware_heartbeat = 0.0
        self._last_attempt = -math.inf
        self._connected_at = 0.0
        self._reported_bad = 0
        self.feedback_published = 0
        self.commands_sent = 0
        self._shutting_down = False
        self._clock_offset_ns: int | None = None

        from aiorobot.msgs.sensor_msgs import JointState
        from aiorobot.msgs.std_msgs import Bool

        self._joint_state_type = JointState
        self.joint_pub = self.create_publisher(JointState, "/joint_states", 10)
        self.create_subscription(JointState, "/wheel_commands", self.on_wheel_command, 10)
        self.create_subscription(Bool, "/estop", self.on_estop, 10)
        self.create_timer(self.heartbeat_period_sec, self.on_heartbeat_timer)

    def __repr__(self) -> str:
        return f"<SerialMotorBridge {self.port} {self.link.state.value}>"

    def statistics(self) -> Any:
        """The link's :class:`LinkStatistics` (frames by kind, bytes, connects)."""
        return self.link.statistics()

    # -- lifecycle -----------------------------------------------------------------------

    async def on_start(self) -> None:
        add_emergency_stop(self.runtime, self.get_fully_qualified_name(), self._emergency_stop)
        self._try_connect(time.monotonic())

    def _emergency_stop(self) -> None:
        """On SIGINT/SIGTERM, before anything else: write a zero wheel command to the port.

        Runs in the runtime's watchdog thread and writes straight to the descriptor, so a
        callback blocking the loop cannot delay it. The leading delimiter ends any frame
        the loop was half-way through, so the firmware decodes this one.
        """
        fd = self.link._fd
        if fd is None or not self.link.connected:
            return
        frame = b"\x00" + encode_message(SetWheelVelocities((0.0,) * len(self.joint_names)), 0)
        try:
            os.write(fd, frame)
        except OSError as err:  # a full or vanished port: the on_shutdown path tries again
            self.get_logger().warning(f"emergency zero command to {self.port} not written: {err}")

    async def on_shutdown(self) -> None:
        remove_emergency_stop(self.runtime, self._emergency_stop)
        self._shutting_down = True
        if self.link.connected:
            self.link.send(SetWheelVelocities((0.0,) * len(self.joint_names)))
            self.link.flush_now()
        self.link.close()

    def _try_connect(self, now: float) -> None:
        self._last_attempt = now
        if not self.link.open():
            self.get_logger().warning(
                f"cannot open {self.port}: {self.link.last_error}; retrying every {self.reconnect_period_sec} s",
                throttle_duration_sec=10.0,
            )
            return
        self._connected_at = now
        self._last_firmware_heartbeat = now  # grace period: one timeout from now
        self._last_ticks = None  # a new session: the firmware's counters start afresh
        self._clock_offset_ns = None
        self.get_logger().info(f"connected to {self.port} at {self.baud_rate} baud")
        self.link.send(HostHeartbeat(self._host_time_ms()))
        self.link.send(VersionRequest())

    def _on_disconnect(self, exc: BaseException) -> None:
        self.firmware_alive = False
        if self._shutting_down:
            self.get_logger().debug(f"{self.port} closed during shutdown: {exc}")  # expected: the other end went first
            return
        self.get_logger().error(f"lost {self.port}: {exc}; reconnecting every {self.reconnect_period_sec} s")

    @staticmethod
    def _host_time_ms() -> int:
        return int(time.monotonic() * 1000) & 0xFFFFFFFF

    # -- periodic: heartbeat, watchdog, reconnect, bad-frame report -----------------------

    def on_heartbeat_timer(self) -> None:
        if self._shutting_down:
            return
        now = time.monotonic()
        if not self.link.connected:
            if now - self._last_attempt >= self.reconnect_period_sec:
                self._try_connect(now)
            return
        self.link.send(HostHeartbeat(self._host_time_ms()))
        if now - self._last_firmware_heartbeat > self.firmware_timeout_sec and not self._estop_by_watchdog:
            self.firmware_alive = False
            self._estop_by_watchdog = True
            self.estop_active = True
            self.link.send(EmergencyStop(EstopReason.FIRMWARE_HEARTBEAT_LOST))
            self.get_logger().error(
                f"no firmware heartbeat on {self.port} for more than {self.firmware_timeout_sec} s: "
                "emergency stop sent"
            )
        stats = self.link.decoder.statistics()
        if stats.bad_frames > self._reported_bad:
            self._reported_bad = stats.bad_frames
            self.get_logger().warning(
                f"bad frames from {self.port}: {stats.crc_errors} CRC, {stats.truncated} truncated, "
                f"{stats.garbage} garbage, {stats.oversize} oversize ({stats.frames_ok} good)",
                throttle_duration_sec=5.0,
            )

    def _on_frame_error(self, error: FrameError) -> None:
        self.get_logger().debug(f"dropped frame from {self.port}: {error}")

    # -- firmware -> host ----------------------------------------------------------------

    def _on_message(self, message: Message) -> None:
        if isinstance(message, EncoderTicks):
            self._on_ticks(message)
        elif isinstance(message, FirmwareHeartbeat):
            self._on_firmware_heartbeat(message)
        elif isinstance(message, VersionResponse):
            self.firmware_version = message
            self.get_logger().info(
                f"firmware {message.name!r} {message.major}.{message.minor}.{message.patch} "
                f"(protocol {message.protocol_version}, {message.wheel_count} wheels, "
                f"{message.ticks_per_revolution} ticks/rev)"
            )
            if message.wheel_count != len(self.joint_names):
                self.get_logger().warning(
                    f"firmware drives {message.wheel_count} wheels but joint_names has {len(self.joint_names)}"
                )
            if self.ticks_per_revolution <= 0.0 and message.ticks_per_revolution > 0:
                self.ticks_per_revolution = float(message.ticks_per_revolution)

    def _on_firmware_heartbeat(self, message: FirmwareHeartbeat) -> None:
        self._last_firmware_heartbeat = time.monotonic()
        if message.status != self.firmware_status:
            self.get_logger().info(f"firmware status {message.status.name or int(message.status)}")
        self.firmware_status = message.status
        if not self.firmware_alive:
            self.firmware_alive = True
            if self._estop_by_watchdog:
                self._estop_by_watchdog = False
                self.estop_active = False
                self.link.send(ClearEmergencyStop())
                self.get_logger().info(f"firmware heartbeat back on {self.port}: emergency stop cleared")

    def _on_ticks(self, message: EncoderTicks) -> None:
        n = len(self.joint_names)
        if len(message.ticks) != n or self.ticks_per_revolution <= 0.0:
            return
        ticks = np.asarray(message.ticks, dtype=np.int64)
        if self._last_ticks is not None:
            delta = np.asarray(tick_delta(ticks, self._last_ticks), dtype=np.float64) * (2.0 * math.pi / self.ticks_per_revolution)
            dt = (message.timestamp_us - self._last_tick_us) * 1e-6
            self.wheel_positions_rad = self.wheel_positions_rad + delta
            if dt > 0.0:
                self.wheel_velocities_rad_s = delta / dt
        self._last_ticks = ticks
        self._last_tick_us = message.timestamp_us
        msg = self._joint_state_type()
        msg.header.stamp = self._stamp_from_firmware(message.timestamp_us).to_msg()
        msg.name = list(self.joint_names)
        msg.position = self.wheel_positions_rad.copy()
        msg.velocity = self.wheel_velocities_rad_s.copy()
        self.joint_pub.publish(msg)
        self.feedback_published += 1

    def _stamp_from_firmware(self, timestamp_us: int) -> Time:
        """Host time of a firmware timestamp: firmware time plus an offset fixed at the first reading.

        Stamps then keep the firmware's even spacing instead of the host's scheduling jitter. The
        offset is re-anchored when the two clocks drift more than ``_MAX_CLOCK_SKEW_NS`` apart.
        """
        now_ns = self.now().nanoseconds
        if self._clock_offset_ns is None or abs(timestamp_us * 1000 + self._clock_offset_ns - now_ns) > _MAX_CLOCK_SKEW_NS:
            self._clock_offset_ns = now_ns - timestamp_us * 1000
        return Time(nanoseconds=timestamp_us * 1000 + self._clock_offset_ns)

    # -- host -> firmware ----------------------------------------------------------------

    def on_wheel_command(self, msg: Any) -> None:
        velocity = np.asarray(msg.velocity, dtype=np.float64)
        names = list(msg.name)
        if names:
            lookup = dict(zip(names, velocity))
            if not all(n in lookup for n in self.joint_names):
                self.get_logger().warning(
                    f"/wheel_commands names {names} do not cover joint_names {self.joint_names}; ignored",
                    throttle_duration_sec=5.0,
                )
                return
            ordered = [float(lookup[n]) for n in self.joint_names]
        elif len(velocity) == len(self.joint_names):
            ordered = [float(v) for v in velocity]
        else:
            self.get_logger().warning(
                f"/wheel_commands has {len(velocity)} velocities for {len(self.joint_names)} wheels; ignored",
                throttle_duration_sec=5.0,
            )
            return
        if not all(math.isfinite(v) for v in ordered):
            self.get_logger().warning(f"/wheel_commands with non-finite velocity {ordered}; ignored", throttle_duration_sec=5.0)
            return
        if self.link.send(SetWheelVelocities(tuple(ordered))):
            self.commands_sent += 1

    def on_estop(self, msg: Any) -> None:
        if msg.data:
            self.estop_active = True
            self.link.send(EmergencyStop(EstopReason.REQUESTED))
            self.get_logger().warning("emergency stop requested on /estop")
        else:
            self.estop_active = False
            self._estop_by_watchdog = False
            self.link.send(ClearEmergencyStop())
            self.get_logger().info("emergency stop cleared on /estop")

    # -- aiorobot run display ---------------------------------------------------------

    def status_line(self) -> str:
        stats = self.link.decoder.statistics()
        return f"serial {self.link.state.value} rx {stats.frames_ok} ok/{stats.bad_frames} bad"

    def summary(self) -> str:
        s = self.link.statistics()
        d = s.decoder
        return (
            f"{self.get_name()}: {self.commands_sent} commands sent, {self.feedback_published} feedback published; "
            f"frames ok {d.frames_ok}, CRC {d.crc_errors}, truncated {d.truncated}, garbage {d.garbage}, "
            f"oversize {d.oversize}, gaps {d.sequence_gaps}; connects {s.connects}, disconnects {s.disconnects}"
        )
