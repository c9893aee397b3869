"""Message-stream statistics: count, rate and delivery latency (a pure core, no runtime)."""

from __future__ import annotations

import threading
from collections import deque
from dataclasses import dataclass

__all__ = ["TopicStatistics", "TopicSummary"]


@dataclass(frozen=True, slots=True)
class TopicSummary:
    """Figures about one topic; rates in Hz, latencies in microseconds (``nan`` when unknown)."""

    count: int
    rate_hz: float
    latency_p50_us: float
    latency_p99_us: float
    latency_max_us: float


class TopicStatistics:
    """Count, rate and latency percentiles of a message stream.

    ``rate_hz`` in :meth:`recent` is over the last ``window_sec`` (as ``ros2 topic hz``:
    intervals between the messages inside the window); latency percentiles are over the
    last ``max_samples`` messages. Thread-safe: the node records on its loop while a
    display reads from another thread.
    """

    def __init__(self, window_sec: float = 1.0, max_samples: int = 1000) -> None:
        if window_sec <= 0.0 or max_samples < 1:
            raise ValueError(
                f"expected window_sec > 0 and max_samples >= 1, found {window_sec!r}, {max_samples!r}"
            )
        self._window_ns = int(window_sec * 1e9)
        self._lock = threading.Lock()
        self._receive_ns: deque[int] = deque()
        self._latency_ns: deque[int] = deque(maxlen=max_samples)
        self._count = 0
        self._first_ns: int | None = None
        self._last_ns: int | None = None
        self._latency_max_ns: int | None = None

    def record(self, receive_ns: int, latency_ns: int) -> None:
        """Account one message received at ``receive_ns`` that took ``latency_ns`` to arrive."""
        with self._lock:
            self._count += 1
            if self._first_ns is None:
                self._first_ns = receive_ns
            self._last_ns = receive_ns
            self._receive_ns.append(receive_ns)
            while self._receive_ns and self._receive_ns[0] < receive_ns - self._window_ns:
                self._receive_ns.popleft()
            self._latency_ns.append(latency_ns)
            if self._latency_max_ns is None or latency_ns > self._latency_max_ns:
                self._latency_max_ns = latency_ns

    def recent(self, now_ns: int) -> TopicSummary:
        """Figures for the last window ending at ``now_ns`` (latency: recent samples, max: ever)."""
        with self._lock:
            times = [t for t in self._receive_ns if t >= now_ns - self._window_ns]
            latencies = sorted(self._latency_ns)
            count, latency_max = self._count, self._latency_max_ns
        if times:
            rate = _rate_hz(times[0], times[-1], len(times))
        else:
            rate = float("nan")
        return _summary(count, rate, latencies, latency_max)

    def total(self) -> TopicSummary:
        """Figures over everything recorded: mean rate between first and last message."""
        with self._lock:
            latencies = sorted(self._latency_ns)
            rate = _rate_hz(self._first_ns, self._last_ns, self._count)
            return _summary(self._count, rate, latencies, self._latency_max_ns)


def _rate_hz(first_ns: int | None, last_ns: int | None, count: int) -> float:
    if first_ns is None or last_ns is None or count < 2 or last_ns <= first_ns:
        return float("nan")
    return (count - 1) * 1e9 / (last_ns - first_ns)


def _percentile(sorted_values: list[int], fraction: float) -> float:
    if not sorted_values:
        return float("nan")
    index = min(len(sorted_values) - 1, int(round(fraction * (len(sorted_values) - 1))))
    return sorted_values[index] / 1e3


def _summary(count: int, rate_hz: float, latencies: list[int], latency_max_ns: int | None) -> TopicSummary:
    return TopicSummary(
        count=count,
        rate_hz=rate_hz,
        latency_p50_us=_percentile(latencies, 0.50),
        latency_p99_us=_percentile(latencies, 0.99),
        latency_max_us=float("nan") if latency_max_ns is None else latency_max_ns / 1e3,
    )
