"""A streaming decoder for the motor protocol: any byte chunks in, good messages out, never raises."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from ._framing import MAX_ENCODED_FRAME_BYTES, FrameError, FrameErrorKind, parse_packet
from ._messages import Message, decode_message

__all__ = ["StreamDecoder", "DecoderStatistics"]


@dataclass(frozen=True, slots=True)
class DecoderStatistics:
    """Counters of a :class:`StreamDecoder` since it was made.

    ``frames_ok`` good messages; ``crc_errors``, ``truncated``, ``garbage`` and
    ``oversize`` dropped frames by kind (see :class:`FrameErrorKind`);
    ``sequence_gaps`` packets missing between consecutive good ones, judged by
    their sequence numbers; ``bytes_received`` every byte fed.
    """

    frames_ok: int = 0
    crc_errors: int = 0
    truncated: int = 0
    garbage: int = 0
    oversize: int = 0
    sequence_gaps: int = 0
    bytes_received: int = 0

    @property
    def bad_frames(self) -> int:
        return self.crc_errors + self.truncated + self.garbage + self.oversize


_FIELD_BY_KIND = {
    FrameErrorKind.CRC: "crc_errors",
    FrameErrorKind.TRUNCATED: "truncated",
    FrameErrorKind.GARBAGE: "garbage",
    FrameErrorKind.OVERSIZE: "oversize",
}


class StreamDecoder:
    """Splits a byte stream on 0x00 delimiters and decodes each frame.

    Feed it chunks of any size, cut anywhere; it returns the good messages in
    order. A bad frame is dropped and counted by kind, and decoding resumes at
    the next delimiter; a frame longer than ``max_frame_bytes`` is dropped as
    soon as it grows past the limit, so memory stays bounded. Empty frames
    (consecutive delimiters) are ignored: a sender may put a 0x00 in front of a
    frame to resynchronise. :meth:`feed` never raises on any input.

    Parameters
    ----------
    on_error : callable, optional
        Called with each :class:`FrameError` (for logging); its exceptions are swallowed.
    max_frame_bytes : int
        Longest encoded frame accepted, delimiter excluded.
    """

    def __init__(
        self,
        *,
        on_error: Callable[[FrameError], object] | None = None,
        max_frame_bytes: int = MAX_ENCODED_FRAME_BYTES,
    ) -> None:
        self._on_error = on_error
        self._max = int(max_frame_bytes)
        self._buffer = bytearray()
        self._discarding = False
        self._counts = dict.fromkeys(DecoderStatistics.__dataclass_fields__, 0)
        self._last_seq: int | None = None
        self.last_error: FrameError | None = None

    def __repr__(self) -> str:
        stats = self.statistics()
        return f"<StreamDecoder ok={stats.frames_ok} bad={stats.bad_frames} buffered={len(self._buffer)}>"

    def statistics(self) -> DecoderStatistics:
        """A snapshot of the counters."""
        return DecoderStatistics(**self._counts)

    def reset(self) -> None:
        """Drop a partial frame and the sequence history (after a reconnect); counters stay."""
        self._buffer.clear()
        self._discarding = False
        self._last_seq = None

    def _error(self, error: FrameError) -> None:
        self._counts[_FIELD_BY_KIND[error.kind]] += 1
        self.last_error = error
        if self._on_error is not None:
            try:
                self._on_error(error)
            except Exception:  # a logging callback must not break decoding
                pass

    def feed(self, data: bytes | bytearray | memoryview) -> list[Message]:
        """Consume ``data`` and return the messages completed by it (possibly none)."""
        try:
            chunk = bytes(data)
        except Exception:
            return []
        self._counts["bytes_received"] += len(chunk)
        messages: list[Message] = []
        start = 0
        while start <= len(chunk):
            end = chunk.find(0, start)
            piece = chunk[start:] if end < 0 else chunk[start:end]
            if not self._discarding:
                self._buffer += piece
                if len(self._buffer) > self._max:
                    self._error(
                        FrameError(
                            FrameErrorKind.OVERSIZE, f"more than {self._max} bytes without a delimiter"
                        )
                    )
                    self._buffer.clear()
                    self._discarding = True
            if end < 0:
                break
            if self._discarding:
                self._discarding = False
            elif self._buffer:
                message = self._decode(bytes(self._buffer))
                if message is not None:
                    messages.append(message)
            self._buffer.clear()
            start = end + 1
        return messages

    def _decode(self, frame: bytes) -> Message | None:
        try:
            packet = parse_packet(frame)
            message = decode_message(packet)
        except FrameError as error:
            self._error(error)
            return None
        except Exception as exc:  # defensive: the decoder must never raise
            self._error(FrameError(FrameErrorKind.GARBAGE, f"undecodable frame: {exc!r}"))
            return None
        if self._last_seq is not None:
            self._counts["sequence_gaps"] += (packet.seq - self._last_seq - 1) % 256
        self._last_seq = packet.seq
        self._counts["frames_ok"] += 1
        return message
