"""Messages of the aiorobot motor serial protocol (version 1), host <-> firmware.

Ids 0x01-0x7F travel host -> firmware, 0x81-0xFF firmware -> host. All
multi-byte fields are little-endian; floats are IEEE-754 binary32.
"""

from __future__ import annotations

import enum
import struct
from dataclasses import dataclass
from typing import Any, ClassVar, Union

from ._framing import MAX_PAYLOAD_BYTES, FrameError, FrameErrorKind, Packet, encode_packet

__all__ = [
    "PROTOCOL_VERSION",
    "MAX_WHEELS",
    "MsgId",
    "FirmwareStatus",
    "EstopReason",
    "SetWheelVelocities",
    "HostHeartbeat",
    "EmergencyStop",
    "ClearEmergencyStop",
    "VersionRequest",
    "ResetEncoders",
    "EncoderTicks",
    "FirmwareHeartbeat",
    "VersionResponse",
    "Message",
    "encode_message",
    "decode_message",
]

PROTOCOL_VERSION = 1
MAX_WHEELS = 8


class MsgId(enum.IntEnum):
    """Message ids; the high bit set means firmware -> host."""

    SET_WHEEL_VELOCITIES = 0x01
    HOST_HEARTBEAT = 0x02
    EMERGENCY_STOP = 0x03
    CLEAR_EMERGENCY_STOP = 0x04
    VERSION_REQUEST = 0x05
    RESET_ENCODERS = 0x06
    ENCODER_TICKS = 0x81
    FIRMWARE_HEARTBEAT = 0x82
    VERSION_RESPONSE = 0x83


class FirmwareStatus(enum.IntFlag):
    """Status bits in :class:`FirmwareHeartbeat`."""

    OK = 0
    ESTOP = 0x01  # an emergency stop is latched; motors held at zero until cleared
    HOST_TIMEOUT = 0x02  # no host heartbeat within the firmware's timeout; motors held at zero
    MOTOR_FAULT = 0x04  # driver fault reported by the hardware


class EstopReason(enum.IntEnum):
    """Why an :class:`EmergencyStop` was sent."""

    REQUESTED = 0  # user or application request
    FIRMWARE_HEARTBEAT_LOST = 1  # the host stopped hearing the firmware
    SHUTDOWN = 2  # the host is shutting down


def _count_prefixed(payload: bytes, header: int, item: int, name: str) -> int:
    if len(payload) < header + 1:
        raise FrameError(FrameErrorKind.GARBAGE, f"{name} payload of {len(payload)} bytes, need at least {header + 1}")
    count = payload[header]
    if not 1 <= count <= MAX_WHEELS or len(payload) != header + 1 + item * count:
        raise FrameError(
            FrameErrorKind.GARBAGE,
            f"{name} with wheel count {count} needs {header + 1 + item * count} payload bytes, got {len(payload)}",
        )
    return count


def _fixed(payload: bytes, size: int, name: str) -> None:
    if len(payload) != size:
        raise FrameError(FrameErrorKind.GARBAGE, f"{name} payload must be {size} bytes, got {len(payload)}")


@dataclass(frozen=True, slots=True)
class SetWheelVelocities:
    """Host -> firmware, 0x01: target wheel speeds in rad/s. Payload ``u8 n, n x f32``."""

    MSG_ID: ClassVar[int] = MsgId.SET_WHEEL_VELOCITIES
    velocities_rad_s: tuple[float, ...]

    def pack(self) -> bytes:
        n = len(self.velocities_rad_s)
        if not 1 <= n <= MAX_WHEELS:
            raise ValueError(f"SetWheelVelocities needs 1..{MAX_WHEELS} wheels, got {n}")
        return struct.pack(f"<B{n}f", n, *self.velocities_rad_s)

    @classmethod
    def unpack(cls, payload: bytes) -> SetWheelVelocities:
        n = _count_prefixed(payload, 0, 4, "SetWheelVelocities")
        return cls(struct.unpack_from(f"<{n}f", payload, 1))


@dataclass(frozen=True, slots=True)
class HostHeartbeat:
    """Host -> firmware, 0x02: 'the host is alive'. Payload ``u32 host_time_ms`` (wraps)."""

    MSG_ID: ClassVar[int] = MsgId.HOST_HEARTBEAT
    host_time_ms: int = 0

    def pack(self) -> bytes:
        return struct.pack("<I", self.host_time_ms & 0xFFFFFFFF)

    @classmethod
    def unpack(cls, payload: bytes) -> HostHeartbeat:
        _fixed(payload, 4, "HostHeartbeat")
        return cls(struct.unpack("<I", payload)[0])


@dataclass(frozen=True, slots=True)
class EmergencyStop:
    """Host -> firmware, 0x03: stop all motors now and latch. Payload ``u8 reason``."""

    MSG_ID: ClassVar[int] = MsgId.EMERGENCY_STOP
    reason: int = EstopReason.REQUESTED

    def pack(self) -> bytes:
        return bytes((int(self.reason) & 0xFF,))

    @classmethod
    def unpack(cls, payload: bytes) -> EmergencyStop:
        _fixed(payload, 1, "EmergencyStop")
        return cls(payload[0])


@dataclass(frozen=True, slots=True)
class _Empty:
    """A message without payload."""

    def pack(self) -> bytes:
        return b""

    @classmethod
    def unpack(cls, payload: bytes) -> Any:
        _fixed(payload, 0, cls.__name__)
        return cls()


@dataclass(frozen=True, slots=True)
class ClearEmergencyStop(_Empty):
    """Host -> firmware, 0x04: release a latched e-stop; motors stay at zero until the next command."""

    MSG_ID: ClassVar[int] = MsgId.CLEAR_EMERGENCY_STOP


@dataclass(frozen=True, slots=True)
class VersionRequest(_Empty):
    """Host -> firmware, 0x05: ask for a :class:`VersionResponse`."""

    MSG_ID: ClassVar[int] = MsgId.VERSION_REQUEST


@dataclass(frozen=True, slots=True)
class ResetEncoders(_Empty):
    """Host -> firmware, 0x06: set every encoder counter to zero."""

    MSG_ID: ClassVar[int] = MsgId.RESET_ENCODERS


@dataclass(frozen=True, slots=True)
class EncoderTicks:
    """Firmware -> host, 0x81: encoder counters. Payload ``u64 timestamp_us, u8 n, n x i32 ticks``.

    ``timestamp_us`` is the firmware's monotonic clock when the counters were latched;
    counters are cumulative and wrap as signed 32-bit integers.
    """

    MSG_ID: ClassVar[int] = MsgId.ENCODER_TICKS
    timestamp_us: int
    ticks: tuple[int, ...]

    def pack(self) -> bytes:
        n = len(self.ticks)
        if not 1 <= n <= MAX_WHEELS:
            raise ValueError(f"EncoderTicks needs 1..{MAX_WHEELS} wheels, got {n}")
        wrapped = [((t + 2**31) % 2**32) - 2**31 for t in self.ticks]
        return struct.pack(f"<QB{n}i", self.timestamp_us, n, *wrapped)

    @classmethod
    def unpack(cls, payload: bytes) -> EncoderTicks:
        n = _count_prefixed(payload, 8, 4, "EncoderTicks")
        timestamp_us, _, *ticks = struct.unpack(f"<QB{n}i", payload)
        return cls(timestamp_us, tuple(ticks))


@dataclass(frozen=True, slots=True)
class FirmwareHeartbeat:
    """Firmware -> host, 0x82: 'the firmware is alive'. Payload ``u32 uptime_ms, u8 status``."""

    MSG_ID: ClassVar[int] = MsgId.FIRMWARE_HEARTBEAT
    uptime_ms: int
    status: FirmwareStatus = FirmwareStatus.OK

    def pack(self) -> bytes:
        return struct.pack("<IB", self.uptime_ms & 0xFFFFFFFF, int(self.status))

    @classmethod
    def unpack(cls, payload: bytes) -> FirmwareHeartbeat:
        _fixed(payload, 5, "FirmwareHeartbeat")
        uptime_ms, status = struct.unpack("<IB", payload)
        return cls(uptime_ms, FirmwareStatus(status))


_VERSION_HEADER = struct.Struct("<BBBBBI")
MAX_NAME_BYTES = 32


@dataclass(frozen=True, slots=True)
class VersionResponse:
    """Firmware -> host, 0x83. Payload ``u8 protocol, u8 major, u8 minor, u8 patch, u8 wheel_count,
    u32 ticks_per_revolution, 0..32 bytes UTF-8 name``."""

    MSG_ID: ClassVar[int] = MsgId.VERSION_RESPONSE
    protocol_version: int
    major: int
    minor: int
    patch: int
    wheel_count: int
    ticks_per_revolution: int
    name: str = ""

    def pack(self) -> bytes:
        name = self.name.encode("utf-8")[:MAX_NAME_BYTES]
        return _VERSION_HEADER.pack(
            self.protocol_version, self.major, self.minor, self.patch, self.wheel_count, self.ticks_per_revolution
        ) + name

    @classmethod
    def unpack(cls, payload: bytes) -> VersionResponse:
        size = _VERSION_HEADER.size
        if not size <= len(payload) <= size + MAX_NAME_BYTES:
            raise FrameError(
                FrameErrorKind.GARBAGE, f"VersionResponse payload must be {size}..{size + MAX_NAME_BYTES} bytes, got {len(payload)}"
            )
        protocol, major, minor, patch, wheels, ticks = _VERSION_HEADER.unpack_from(payload)
        name = payload[size:].decode("utf-8", errors="replace")
        return cls(protocol, major, minor, patch, wheels, ticks, name=name)


Message = Union[
    SetWheelVelocities,
    HostHeartbeat,
    EmergencyStop,
    ClearEmergencyStop,
    VersionRequest,
    ResetEncoders,
    EncoderTicks,
    FirmwareHeartbeat,
    VersionResponse,
]

_BY_ID: dict[int, Any] = {
    cls.MSG_ID: cls
    for cls in (
        SetWheelVelocities,
        HostHeartbeat,
        EmergencyStop,
        ClearEmergencyStop,
        VersionRequest,
        ResetEncoders,
        EncoderTicks,
        FirmwareHeartbeat,
        VersionResponse,
    )
}
assert MAX_PAYLOAD_BYTES >= 8 + 1 + 4 * MAX_WHEELS


def encode_message(message: Message, seq: int) -> bytes:
    """The framed on-wire bytes of ``message`` with sequence number ``seq`` (mod 256)."""
    return encode_packet(message.MSG_ID, seq, message.pack())


def decode_message(packet: Packet) -> Message:
    """The message a good packet carries.

    Raises
    ------
    FrameError
        Kind ``GARBAGE`` for an unknown id or a payload of the wrong length.
    """
    cls = _BY_ID.get(packet.msg_id)
    if cls is None:
        raise FrameError(FrameErrorKind.GARBAGE, f"unknown message id 0x{packet.msg_id:02X}")
    try:
        message: Message = cls.unpack(packet.payload)
        return message
    except (struct.error, ValueError) as exc:
        if isinstance(exc, FrameError):
            raise
        raise FrameError(FrameErrorKind.GARBAGE, f"bad payload for {cls.__name__}: {exc}") from None
