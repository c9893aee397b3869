"""The flight recorder's memory: a ring buffer of serialised messages bounded in bytes.

rosbag2's snapshot mode (``ros2 bag record --snapshot-mode --max-cache-size``) keeps the most
recent messages of every recorded topic in a circular cache and writes them only when asked
(``~/snapshot``). This is that cache: messages in arrival order, the oldest dropped as soon as
the total of their sizes would pass ``max_bytes``, so a snapshot holds the last ``max_bytes``
worth of recording across all topics (one time window, every topic in it).

``push`` is called in the publishing threads (a recorder's taps) and ``take`` on the loop: a
lock guards the deque; a push costs one append and, once full, about one popleft.
"""

from __future__ import annotations

import threading
from collections import deque
from dataclasses import dataclass

__all__ = ["SnapshotBuffer", "SnapshotBufferStatistics"]


@dataclass(frozen=True, slots=True)
class SnapshotBufferStatistics:
    """What the buffer holds now and has dropped (pushed out by newer messages) so far."""

    messages: int
    bytes: int
    dropped: int
    max_bytes: int


class SnapshotBuffer:
    """The last ``max_bytes`` of ``(topic, time_ns, cdr)`` messages; ``take()`` empties it."""

    def __init__(self, max_bytes: int) -> None:
        if max_bytes <= 0:
            raise ValueError(f"snapshot buffer: max_bytes must be > 0, found {max_bytes!r}")
        self.max_bytes = int(max_bytes)
        self._items: deque[tuple[str, int, bytes]] = deque()
        self._bytes = 0
        self._dropped = 0
        self._lock = threading.Lock()

    def __repr__(self) -> str:
        return f"<SnapshotBuffer {len(self._items)} messages {self._bytes}/{self.max_bytes} bytes>"

    def push(self, topic: str, time_ns: int, data: bytes) -> None:
        """Keep one message, dropping the oldest ones it pushes past ``max_bytes`` (a message larger
        than the whole buffer is dropped at once: it cannot be held)."""
        size = len(data)
        with self._lock:
            if size > self.max_bytes:
                self._dropped += 1
                return
            items = self._items
            items.append((topic, time_ns, data))
            self._bytes += size
            while self._bytes > self.max_bytes:
                self._bytes -= len(items.popleft()[2])
                self._dropped += 1

    def take(self) -> list[tuple[str, int, bytes]]:
        """Everything held, oldest first; the buffer is empty afterwards."""
        with self._lock:
            items, self._items = list(self._items), deque()
            self._bytes = 0
        return items

    def statistics(self) -> SnapshotBufferStatistics:
        with self._lock:
            return SnapshotBufferStatistics(len(self._items), self._bytes, self._dropped, self.max_bytes)
