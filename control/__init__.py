"""aiorobot.control: kinematics, controllers, the serial motor protocol and bridge, a simulated firmware.

Pure cores (numpy in, numpy out, no runtime): :class:`DiffDrive`, :class:`Mecanum`,
:func:`saturate_wheel_speeds`, :func:`integrate_twist`, :class:`WheelOdometry`,
:class:`PID`, :class:`VelocitySmoother`, :class:`GoToGoal`, :class:`PurePursuit`.
"""

from __future__ import annotations

from ._decoder import DecoderStatistics, StreamDecoder
from ._framing import (
    MAX_ENCODED_FRAME_BYTES,
    MAX_PAYLOAD_BYTES,
    CobsError,
    FrameError,
    FrameErrorKind,
    Packet,
    cobs_decode,
    cobs_encode,
    crc16_ccitt_false,
    encode_packet,
    parse_packet,
)
from ._go_to_goal import DriveCommand, GoToGoal
from ._kinematics import DiffDrive, Kinematics, Mecanum, saturate_wheel_speeds
from ._messages import (
    MAX_WHEELS,
    PROTOCOL_VERSION,
    ClearEmergencyStop,
    EmergencyStop,
    EncoderTicks,
    EstopReason,
    FirmwareHeartbeat,
    FirmwareStatus,
    HostHeartbeat,
    Message,
    MsgId,
    ResetEncoders,
    SetWheelVelocities,
    VersionRequest,
    VersionResponse,
    decode_message,
    encode_message,
)
from ._odometry import WheelOdometry, integrate_twist, tick_delta, wrap_angle
from ._pid import PID
from ._pure_pursuit import PurePursuit, check_path
from ._serial_link import LinkState, LinkStatistics, SerialLink
from ._sim_firmware import PtyFirmware, SimulatedFirmware
from ._smoother import VelocitySmoother

__all__ = [
    "check_path",
    "ClearEmergencyStop",
    "cobs_decode",
    "cobs_encode",
    "CobsError",
    "crc16_ccitt_false",
    "decode_message",
    "DecoderStatistics",
    "DiffDrive",
    "DriveCommand",
    "EmergencyStop",
    "encode_message",
    "encode_packet",
    "EncoderTicks",
    "EstopReason",
    "FirmwareHeartbeat",
    "FirmwareStatus",
    "FrameError",
    "FrameErrorKind",
    "GoToGoal",
    "HostHeartbeat",
    "integrate_twist",
    "Kinematics",
    "MAX_ENCODED_FRAME_BYTES",
    "MAX_PAYLOAD_BYTES",
    "MAX_WHEELS",
    "LinkState",
    "LinkStatistics",
    "Mecanum",
    "Message",
    "MsgId",
    "Packet",
    "parse_packet",
    "PID",
    "PROTOCOL_VERSION",
    "PtyFirmware",
    "PurePursuit",
    "ResetEncoders",
    "saturate_wheel_speeds",
    "SerialLink",
    "SetWheelVelocities",
    "SimulatedFirmware",
    "StreamDecoder",
    "tick_delta",
    "VelocitySmoother",
    "VersionRequest",
    "VersionResponse",
    "WheelOdometry",
    "wrap_angle",
]
