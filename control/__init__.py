"""aiorobot.control: kinematics, controllers, the serial motor protocol and bridge, a simulated firmware.

Pure cores (numpy in, numpy out, no runtime): :class:`DiffDrive`, :class:`Mecanum`,
:func:`saturate_wheel_speeds`, :func:`integrate_twist`, :class:`WheelOdometry`,
:class:`PID`, :class:`VelocitySmoother`, :class:`GoToGoal`, :class:`PurePursuit`.

Serial motor protocol (``docs/serial-protocol.md``): framing (:func:`encode_message`,
:class:`StreamDecoder`), messages, :class:`SerialLink`, and a simulated firmware
(:class:`SimulatedFirmware`, :class:`PtyFirmware`).

Nodes: :class:`DiffDriveController`, :class:`MecanumController`,
:class:`SerialMotorBridge`, :class:`SimulatedFirmwareNode`, :class:`GoToGoalController`,
:class:`PurePursuitController`.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

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

# Nodes import the runtime; they load on first use so the pure cores stay importable alone.
_NODES = {
    "BaseController": "._base_controller",
    "DiffDriveController": "._base_controller",
    "MecanumController": "._base_controller",
    "odometry_message": "._base_controller",
    "SerialMotorBridge": "._serial_bridge",
    "SimulatedFirmwareNode": "._sim_firmware_node",
    "GoToGoalController": "._follower_nodes",
    "PurePursuitController": "._follower_nodes",
    "path_from_msg": "._follower_nodes",
    "pose_from_msg": "._follower_nodes",
}

if TYPE_CHECKING:
    from ._base_controller import BaseController, DiffDriveController, MecanumController, odometry_message
    from ._follower_nodes import GoToGoalController, PurePursuitController, path_from_msg, pose_from_msg
    from ._serial_bridge import SerialMotorBridge
    from ._sim_firmware_node import SimulatedFirmwareNode


def __getattr__(name: str) -> Any:
    module = _NODES.get(name)
    if module is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(module, __name__), name)
    globals()[name] = value
    return value


__all__ = [
    "BaseController",
    "check_path",
    "ClearEmergencyStop",
    "cobs_decode",
    "cobs_encode",
    "CobsError",
    "crc16_ccitt_false",
    "decode_message",
    "DecoderStatistics",
    "DiffDrive",
    "DiffDriveController",
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
    "GoToGoalController",
    "HostHeartbeat",
    "integrate_twist",
    "Kinematics",
    "LinkState",
    "LinkStatistics",
    "MAX_ENCODED_FRAME_BYTES",
    "MAX_PAYLOAD_BYTES",
    "MAX_WHEELS",
    "Mecanum",
    "MecanumController",
    "Message",
    "MsgId",
    "odometry_message",
    "Packet",
    "parse_packet",
    "path_from_msg",
    "PID",
    "pose_from_msg",
    "PROTOCOL_VERSION",
    "PtyFirmware",
    "PurePursuit",
    "PurePursuitController",
    "ResetEncoders",
    "saturate_wheel_speeds",
    "SerialLink",
    "SerialMotorBridge",
    "SetWheelVelocities",
    "SimulatedFirmware",
    "SimulatedFirmwareNode",
    "StreamDecoder",
    "tick_delta",
    "VelocitySmoother",
    "VersionRequest",
    "VersionResponse",
    "WheelOdometry",
    "wrap_angle",
]
