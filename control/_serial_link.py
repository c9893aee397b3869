"""A non-blocking serial link for the motor protocol, driven by an asyncio loop.

pyserial does the port handling (open, termios set-up, read, write) on a file
descriptor in non-blocking mode; the loop watches the descriptor with
``add_reader`` / ``add_writer``, so neither reads nor writes ever block it.
"""

from __future__ import annotations

import asyncio
import enum
import select
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from ._decoder import DecoderStatistics, StreamDecoder
from ._framing import FrameError
from ._messages import Message, encode_message

__all__ = ["SerialLink", "LinkState", "LinkStatistics"]

#: Bytes kept waiting for a slow port before the oldest are dropped: stale motor
#: commands are worse than none.
MAX_PENDING_BYTES = 4096


class LinkState(enum.Enum):
    DISCONNECTED = "disconnected"
    CONNECTED = "connected"
    CLOSED = "closed"


@dataclass(frozen=True, slots=True)
class LinkStatistics:
    """Counters of a :class:`SerialLink`: receive side from its decoder, plus transmit and link events."""

    state: LinkState
    decoder: DecoderStatistics
    packets_sent: int
    bytes_sent: int
    bytes_dropped: int
    connects: int
    disconnects: int


class SerialLink:
    """One serial port speaking the motor protocol, opened and re-opened on demand.

    Call every method from the thread of the loop it runs on. ``open()`` tries
    once and returns whether it succeeded; the owner decides when to retry.
    A read or write error (the device went away) closes the port, calls
    ``on_disconnect`` and leaves the link ``DISCONNECTED``.

    Parameters
    ----------
    port : str
        Device path or pyserial URL (``/dev/ttyUSB0``, a pty slave, ``loop://``).
    baud_rate : int
        Line speed.
    on_message : callable
        Called with every good :class:`Message` received.
    on_frame_error : callable, optional
        Called with every dropped frame's :class:`FrameError`.
    on_disconnect : callable, optional
        Called with the exception when the port fails.
    """

    def __init__(
        self,
        port: str,
        baud_rate: int,
        *,
        on_message: Callable[[Message], object],
        on_frame_error: Callable[[FrameError], object] | None = None,
        on_disconnect: Callable[[BaseException], object] | None = None,
    ) -> None:
        self.port = port
        self.baud_rate = int(baud_rate)
        self._on_message = on_message
        self._on_disconnect = on_disconnect
        self.decoder = StreamDecoder(on_error=on_frame_error)
        self.state = LinkState.DISCONNECTED
        self.last_error: BaseException | None = None
        self._serial: Any = None
        self._fd: int | None = None
        self._loop: asyncio.AbstractEventLoop | None = None
        self._pending = bytearray()
        self._writer_armed = False
        self._seq = 0
        self._packets_sent = 0
        self._bytes_sent = 0
        self._bytes_dropped = 0
        self._connects = 0
        self._disconnects = 0

    def __repr__(self) -> str:
        return f"<SerialLink {self.port} {self.baud_rate} baud {self.state.value}>"

    @property
    def connected(self) -> bool:
        return self.state is LinkState.CONNECTED

    def statistics(self) -> LinkStatistics:
        return LinkStatistics(
            self.state,
            self.decoder.statistics(),
            self._packets_sent,
            self._bytes_sent,
            self._bytes_dropped,
            self._connects,
            self._disconnects,
        )

    def open(self) -> bool:
        """Try to open the port now; True when connected (also if it already was)."""
        import serial

        if self.state is LinkState.CLOSED:
            raise RuntimeError(f"{self!r} is closed; make a new SerialLink")
        if self.connected:
            return True
        self._loop = asyncio.get_running_loop()
        try:
            # devices: non-blocking writes (the loop waits for writability); URL handlers such
            # as loop:// emulate line timing and need a blocking write, which they never delay
            write_timeout = None if "://" in self.port else 0
            port = serial.serial_for_url(self.port, self.baud_rate, timeout=0, write_timeout=write_timeout)
        except (serial.SerialException, OSError, ValueError) as exc:
            self.last_error = exc
            return False
        self._serial = port
        self.decoder.reset()
        self._pending.clear()
        try:
            self._fd = port.fileno()
        except Exception:  # URL handlers without a descriptor (loop://) are polled by the owner
            self._fd = None
        if self._fd is not None:
            self._loop.add_reader(self._fd, self._on_readable)
        self.state = LinkState.CONNECTED
        self._connects += 1
        self.send_raw(b"\x00")  # flush any half frame at the other end
        return True

    def poll(self) -> None:
        """Read whatever is waiting (only needed for ports without a file descriptor)."""
        if self.connected and self._fd is None:
            self._on_readable()

    def send(self, message: Message) -> bool:
        """Queue one message for sending; False when the link is down (the message is dropped)."""
        if not self.connected:
            return False
        self._packets_sent += 1
        frame = encode_message(message, self._seq)
        self._seq = (self._seq + 1) & 0xFF
        return self.send_raw(frame)

    def send_raw(self, data: bytes) -> bool:
        """Queue raw bytes (already framed); False when the link is down."""
        if not self.connected:
            return False
        self._pending += data
        overflow = len(self._pending) - MAX_PENDING_BYTES
        if overflow > 0:
            del self._pending[:overflow]
            self._bytes_dropped += overflow
        self._flush()
        return True

    def _flush(self) -> None:
        while self._pending and self.connected:
            if self._fd is not None:
                try:
                    _, writable, _ = select.select([], [self._fd], [], 0)
                except (OSError, ValueError) as exc:
                    self._fail(exc)
                    return
                if not writable:
                    self._arm_writer()
                    return
            try:
                written = self._serial.write(bytes(self._pending))
            except Exception as exc:  # SerialException, OSError: the device went away
                self._fail(exc)
                return
            if not written:
                self._arm_writer()
                return
            del self._pending[:written]
            self._bytes_sent += written
        self._disarm_writer()

    def _arm_writer(self) -> None:
        if not self._writer_armed and self._fd is not None and self._loop is not None:
            self._loop.add_writer(self._fd, self._flush)
            self._writer_armed = True

    def _disarm_writer(self) -> None:
        if self._writer_armed and self._fd is not None and self._loop is not None:
            self._loop.remove_writer(self._fd)
        self._writer_armed = False

    def _on_readable(self) -> None:
        if not self.connected:
            return
        try:
            data = self._serial.read(4096)
        except Exception as exc:  # SerialException on EIO / hang-up: the device went away
            self._fail(exc)
            return
        if not data:
            return
        for message in self.decoder.feed(data):
            try:
                self._on_message(message)
            except Exception:  # the owner's handler must not take the link down
                pass

    def _release(self) -> None:
        if self._fd is not None and self._loop is not None:
            self._disarm_writer()
            self._loop.remove_reader(self._fd)
        self._fd = None
        if self._serial is not None:
            try:
                self._serial.close()
            except Exception:
                pass
        self._serial = None
        self._pending.clear()

    def _fail(self, exc: BaseException) -> None:
        self.last_error = exc
        self._release()
        self.state = LinkState.DISCONNECTED
        self._disconnects += 1
        if self._on_disconnect is not None:
            try:
                self._on_disconnect(exc)
            except Exception:
                pass

    def flush_now(self) -> None:
        """Try once more to write what is pending (used right before closing)."""
        self._flush()

    def close(self) -> None:
        """Release the port for good."""
        if self.connected:
            self._flush()
        self._release()
        self.state = LinkState.CLOSED
