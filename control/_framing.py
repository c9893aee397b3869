"""Serial framing: CRC-16/CCITT-FALSE, COBS, and packets ``id | seq | payload | crc``.

See ``docs/serial-protocol.md`` for the byte layout a firmware must follow.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass

__all__ = [
    "crc16_ccitt_false",
    "cobs_encode",
    "cobs_decode",
    "CobsError",
    "Packet",
    "encode_packet",
    "parse_packet",
    "FrameError",
    "FrameErrorKind",
    "MAX_PAYLOAD_BYTES",
    "MAX_ENCODED_FRAME_BYTES",
    "PACKET_OVERHEAD_BYTES",
]

#: Largest payload a packet may carry.
MAX_PAYLOAD_BYTES = 64
#: id (1) + sequence (1) + CRC (2).
PACKET_OVERHEAD_BYTES = 4
#: Largest COBS-encoded frame, delimiter excluded: one code byte per 254 data bytes, plus one.
MAX_ENCODED_FRAME_BYTES = MAX_PAYLOAD_BYTES + PACKET_OVERHEAD_BYTES + 1 + (MAX_PAYLOAD_BYTES + PACKET_OVERHEAD_BYTES) // 254


def _make_crc_table() -> tuple[int, ...]:
    table = []
    for byte in range(256):
        crc = byte << 8
        for _ in range(8):
            crc = ((crc << 1) ^ 0x1021) if crc & 0x8000 else (crc << 1)
            crc &= 0xFFFF
        table.append(crc)
    return tuple(table)


_CRC_TABLE = _make_crc_table()


def crc16_ccitt_false(data: bytes | bytearray | memoryview, crc: int = 0xFFFF) -> int:
    """CRC-16/CCITT-FALSE: poly 0x1021, init 0xFFFF, no reflection, no final xor.

    ``crc16_ccitt_false(b"123456789") == 0x29B1``.
    """
    table = _CRC_TABLE
    for byte in bytes(data):
        crc = ((crc << 8) & 0xFFFF) ^ table[((crc >> 8) ^ byte) & 0xFF]
    return crc


class CobsError(ValueError):
    """A COBS frame whose code bytes do not fit its length (a truncated frame), or that holds a zero."""


def cobs_encode(data: bytes | bytearray) -> bytes:
    """Consistent Overhead Byte Stuffing: the result holds no zero byte (the delimiter is not appended).

    Canonical COBS (Cheshire and Baker 1999): a run of 254 non-zero bytes ending the data is not
    followed by an empty block.
    """
    out = bytearray([0])
    code_index = 0
    code = 1
    length = len(data)
    for position, byte in enumerate(data):
        if byte == 0:
            out[code_index] = code
            code_index = len(out)
            out.append(0)
            code = 1
            continue
        out.append(byte)
        code += 1
        if code == 0xFF and position + 1 < length:
            out[code_index] = code
            code_index = len(out)
            out.append(0)
            code = 1
    out[code_index] = code
    return bytes(out)


def cobs_decode(frame: bytes | bytearray) -> bytes:
    """Invert :func:`cobs_encode` on one frame without its delimiter.

    Raises
    ------
    CobsError
        If a code byte announces more bytes than the frame holds, or the frame holds a zero.
    """
    out = bytearray()
    index = 0
    length = len(frame)
    while index < length:
        code = frame[index]
        if code == 0:
            raise CobsError(f"zero byte inside a COBS frame at offset {index}")
        end = index + code
        if end > length:
            raise CobsError(f"COBS block at offset {index} announces {code - 1} bytes, only {length - index - 1} left")
        block = frame[index + 1 : end]
        if 0 in block:
            raise CobsError(f"zero byte inside a COBS frame at offset {index + 1 + block.index(0)}")
        out += block
        index = end
        if code != 0xFF and index < length:
            out.append(0)
    return bytes(out)


@dataclass(frozen=True, slots=True)
class Packet:
    """One decoded packet: message id, sequence number (0-255) and payload bytes."""

    msg_id: int
    seq: int
    payload: bytes

    def __repr__(self) -> str:
        return f"<Packet id=0x{self.msg_id:02X} seq={self.seq} payload={self.payload.hex(' ') or '-'}>"


def encode_packet(msg_id: int, seq: int, payload: bytes = b"") -> bytes:
    """The on-wire bytes of a packet: COBS(id, seq, payload, crc16 little-endian) followed by 0x00."""
    if not 0 <= msg_id <= 0xFF:
        raise ValueError(f"msg_id must be 0..255, got {msg_id!r}")
    if len(payload) > MAX_PAYLOAD_BYTES:
        raise ValueError(f"payload must be at most {MAX_PAYLOAD_BYTES} bytes, got {len(payload)}")
    body = bytes((msg_id, seq & 0xFF)) + bytes(payload)
    crc = crc16_ccitt_false(body)
    return cobs_encode(body + crc.to_bytes(2, "little")) + b"\x00"


class FrameErrorKind(enum.Enum):
    """Why a frame was dropped."""

    CRC = "crc"  # decoded fine, CRC mismatch
    TRUNCATED = "truncated"  # COBS block overruns the frame, or fewer than 4 decoded bytes
    GARBAGE = "garbage"  # CRC good but not a protocol message (unknown id, wrong payload length)
    OVERSIZE = "oversize"  # more than MAX_ENCODED_FRAME_BYTES before a delimiter


class FrameError(ValueError):
    """A frame that is not a good packet; ``kind`` says why."""

    def __init__(self, kind: FrameErrorKind, detail: str) -> None:
        super().__init__(f"{kind.value}: {detail}")
        self.kind = kind
        self.detail = detail


def parse_packet(frame: bytes | bytearray) -> Packet:
    """Decode one COBS frame (no delimiter) into a :class:`Packet`, checking length and CRC.

    Raises
    ------
    FrameError
        With kind ``OVERSIZE``, ``TRUNCATED`` or ``CRC``.
    """
    if len(frame) > MAX_ENCODED_FRAME_BYTES:
        raise FrameError(FrameErrorKind.OVERSIZE, f"{len(frame)} encoded bytes, at most {MAX_ENCODED_FRAME_BYTES}")
    try:
        raw = cobs_decode(frame)
    except CobsError as exc:
        raise FrameError(FrameErrorKind.TRUNCATED, str(exc)) from None
    if len(raw) < PACKET_OVERHEAD_BYTES:
        raise FrameError(FrameErrorKind.TRUNCATED, f"{len(raw)} decoded bytes, need at least {PACKET_OVERHEAD_BYTES}")
    received = int.from_bytes(raw[-2:], "little")
    computed = crc16_ccitt_false(raw[:-2])
    if received != computed:
        raise FrameError(FrameErrorKind.CRC, f"CRC 0x{received:04X} received, 0x{computed:04X} computed")
    return Packet(raw[0], raw[1], bytes(raw[2:-2]))
