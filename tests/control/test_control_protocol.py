from __future__ import annotations

import struct

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from aiorobot.control import (
    MAX_ENCODED_FRAME_BYTES,
    ClearEmergencyStop,
    EmergencyStop,
    EncoderTicks,
    FirmwareHeartbeat,
    FirmwareStatus,
    FrameError,
    FrameErrorKind,
    HostHeartbeat,
    SetWheelVelocities,
    StreamDecoder,
    VersionRequest,
    VersionResponse,
    cobs_decode,
    cobs_encode,
    crc16_ccitt_false,
    decode_message,
    encode_message,
    encode_packet,
    parse_packet,
)

MESSAGES = [
    SetWheelVelocities((1.0, -2.0, 3.5, 0.25)),
    HostHeartbeat(123456),
    EmergencyStop(1),
    ClearEmergencyStop(),
    VersionRequest(),
    EncoderTicks(10**12, (1, -5, 2**31 - 1, -(2**31))),
    FirmwareHeartbeat(99, FirmwareStatus.ESTOP | FirmwareStatus.HOST_TIMEOUT),
    VersionResponse(1, 0, 2, 3, 4, 4096, "sim-firmware"),
]


def test_crc16_ccitt_false_check_value():
    assert crc16_ccitt_false(b"123456789") == 0x29B1
    assert crc16_ccitt_false(b"") == 0xFFFF


@pytest.mark.parametrize(
    ("raw", "encoded"),
    [
        (b"", b"\x01"),
        (b"\x00", b"\x01\x01"),
        (b"\x00\x00", b"\x01\x01\x01"),
        (b"\x11\x22\x00\x33", b"\x03\x11\x22\x02\x33"),
        (b"\x11\x00\x00\x00", b"\x02\x11\x01\x01\x01"),
        (bytes(range(1, 255)), b"\xff" + bytes(range(1, 255))),
        (bytes(range(1, 256)), b"\xff" + bytes(range(1, 255)) + b"\x02\xff"),
    ],
)
def test_cobs_matches_reference_examples(raw, encoded):
    assert cobs_encode(raw) == encoded
    assert cobs_decode(encoded) == raw


@settings(derandomize=True)
@given(st.binary(max_size=700))
def test_cobs_roundtrip_and_no_zero_bytes(data):
    encoded = cobs_encode(data)
    assert 0 not in encoded
    assert cobs_decode(encoded) == data


def test_documented_example_frame():
    # the example in docs/serial-protocol.md
    frame = encode_message(SetWheelVelocities((1.0, -1.0)), 7)
    assert frame.hex(" ") == "04 01 07 02 01 03 80 3f 01 05 80 bf 40 26 00"


@pytest.mark.parametrize("message", MESSAGES, ids=lambda m: type(m).__name__)
def test_every_message_roundtrips(message):
    frame = encode_message(message, 200)
    assert frame.endswith(b"\x00") and 0 not in frame[:-1]
    assert len(frame) - 1 <= MAX_ENCODED_FRAME_BYTES
    packet = parse_packet(frame[:-1])
    assert packet.seq == 200
    assert decode_message(packet) == message


def test_parse_packet_reports_crc_failure():
    frame = bytearray(encode_packet(0x02, 1, struct.pack("<I", 5))[:-1])
    frame[3] ^= 0x10
    with pytest.raises(FrameError, match=r"^crc: CRC 0x[0-9A-F]{4} received, 0x[0-9A-F]{4} computed$") as info:
        parse_packet(bytes(frame))
    assert info.value.kind is FrameErrorKind.CRC


def test_decoder_counts_each_kind_and_keeps_good_frames():
    good = encode_message(HostHeartbeat(1), 0)
    crc_bad = bytearray(encode_message(HostHeartbeat(2), 1))
    crc_bad[2] ^= 0xFF if crc_bad[2] != 0xFF else 0x01
    truncated = b"\x07\x01\x00" + b"\x03\x01\x02\x00"  # a block cut short; a 2-byte packet
    unknown = encode_packet(0x42, 3, b"abc")
    wrong_length = encode_packet(0x02, 4, b"\x01\x02")
    oversize = b"\x05" * (MAX_ENCODED_FRAME_BYTES + 10) + b"\x00"
    stream = good + bytes(crc_bad) + truncated + unknown + wrong_length + oversize + good
    decoder = StreamDecoder()
    messages = decoder.feed(stream)
    assert messages == [HostHeartbeat(1), HostHeartbeat(1)]
    stats = decoder.statistics()
    assert (stats.crc_errors, stats.truncated, stats.garbage, stats.oversize) == (1, 2, 2, 1)
    assert stats.frames_ok == 2 and stats.bad_frames == 6


def test_decoder_handles_frames_split_across_chunks_and_counts_sequence_gaps():
    stream = b"".join(encode_message(HostHeartbeat(i), seq) for i, seq in enumerate([0, 1, 2, 5, 6]))
    decoder = StreamDecoder()
    out = []
    for i in range(0, len(stream), 3):
        out += decoder.feed(stream[i : i + 3])
    assert out == [HostHeartbeat(i) for i in range(5)]
    assert decoder.statistics().sequence_gaps == 2


def test_decoder_error_callback_sees_every_bad_frame():
    seen = []
    decoder = StreamDecoder(on_error=seen.append)
    decoder.feed(b"\x07\x01\x00" + encode_packet(0x42, 0))
    assert [e.kind for e in seen] == [FrameErrorKind.TRUNCATED, FrameErrorKind.GARBAGE]


GOOD_FRAMES = [encode_message(m, i) for i, m in enumerate(MESSAGES)]


@settings(max_examples=300, deadline=None, derandomize=True)
@given(noise=st.binary(max_size=400), chunk_sizes=st.lists(st.integers(1, 64), min_size=1, max_size=20))
def test_fuzz_decoder_never_raises_and_recovers_on_next_good_frame(noise, chunk_sizes):
    decoder = StreamDecoder()
    stream = noise + b"\x00" + b"".join(GOOD_FRAMES)
    out = []
    position = 0
    i = 0
    while position < len(stream):
        size = chunk_sizes[i % len(chunk_sizes)]
        out += decoder.feed(stream[position : position + size])
        position += size
        i += 1
    # whatever the noise did, every good frame after the delimiter comes through, in order
    assert out[-len(MESSAGES) :] == MESSAGES
    stats = decoder.statistics()
    assert stats.bytes_received == len(stream)


@settings(max_examples=300, deadline=None, derandomize=True)
@given(
    flips=st.lists(st.tuples(st.integers(0, 10_000), st.integers(1, 255)), max_size=8),
    cuts=st.lists(st.integers(0, 10_000), max_size=4),
)
def test_fuzz_corrupted_frames_never_raise_and_later_frames_survive(flips, cuts):
    stream = bytearray(b"".join(GOOD_FRAMES))
    for offset, mask in flips:
        stream[offset % len(stream)] ^= mask
    for offset in sorted(cuts, reverse=True):
        del stream[offset % len(stream)]
    decoder = StreamDecoder()
    decoder.feed(bytes(stream))
    # a cut may have eaten the last delimiter, so the 0x00 may complete one more (good or bad) frame
    assert decoder.feed(b"\x00" + GOOD_FRAMES[0])[-1:] == [MESSAGES[0]]
    stats = decoder.statistics()
    assert stats.frames_ok + stats.bad_frames >= 1
