"""The Python ``message_filters`` policies, and the C++ ``ApproximateEpsilonTime``. Pure, no runtime.

ROS 2's Python ``message_filters`` package (what rclpy users and the tutorials
use) matches messages differently from the C++ policies in :mod:`._policies`:
every input keeps a stamp-keyed queue, and a set is delivered as soon as one
exists, without waiting for a newer message; out-of-order input is fine.
:class:`PythonExactTimePolicy` and :class:`PythonApproximateTimePolicy` port
that behaviour; :class:`ApproximateEpsilonTimePolicy` ports the C++
``sync_policies::ApproximateEpsilonTime``. Like the C++ ports, ``add(index,
stamp_ns, item)`` returns the sets the item completed, each a tuple with one
item per input in input order.
"""

from __future__ import annotations

import itertools
from collections import deque
from typing import Any, Generic, TypeVar

from ._policies import _check_index, _check_inputs

__all__ = ["ApproximateEpsilonTimePolicy", "PythonApproximateTimePolicy", "PythonExactTimePolicy"]

T = TypeVar("T")


def _check_ns(name: str, value: Any) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < 0:
        raise ValueError(f"{name}: expected an int >= 0 (nanoseconds), got {value!r}")
    return value


class _StampQueues(Generic[T]):
    """Per input a ``{stamp_ns: item}`` queue holding at most ``queue_size`` stamps (oldest dropped)."""

    def __init__(self, n_inputs: int, queue_size: int) -> None:
        _check_inputs(n_inputs, queue_size, allow_zero_queue=False)
        self.n_inputs = n_inputs
        self.queue_size = queue_size
        self._queues: list[dict[int, T]] = [{} for _ in range(n_inputs)]
        self.dropped = 0

    def queued(self, index: int) -> int:
        """How many items input ``index`` holds."""
        _check_index(index, self.n_inputs)
        return len(self._queues[index])

    def clear(self) -> None:
        for q in self._queues:
            q.clear()

    def _insert(self, index: int, stamp_ns: int, item: T) -> None:
        _check_index(index, self.n_inputs)
        q = self._queues[index]
        q[stamp_ns] = item  # a second item with the same stamp replaces the first
        while len(q) > self.queue_size:
            del q[min(q)]
            self.dropped += 1

    def _take(self, stamps: list[int]) -> tuple[T, ...]:
        return tuple(q.pop(s) for q, s in zip(self._queues, stamps))


class PythonExactTimePolicy(_StampQueues[T]):
    """Sets of items with exactly equal stamps, as the Python ``message_filters.TimeSynchronizer``.

    Each input keeps its last ``queue_size`` stamps (the oldest is dropped when
    full). Whenever a stamp is present on every input, that set is output;
    several sets completed by one item come out oldest first. Unlike the C++
    ``ExactTime`` policy (:class:`ExactTimePolicy`) nothing is dropped because a
    newer set completed, so inputs may arrive out of stamp order.
    """

    def __repr__(self) -> str:
        return f"<PythonExactTimePolicy inputs={self.n_inputs} queue_size={self.queue_size}>"

    def add(self, index: int, stamp_ns: int, item: T) -> list[tuple[T, ...]]:
        """Add ``item`` (stamped ``stamp_ns``) on input ``index``; return the sets completed by it."""
        self._insert(index, stamp_ns, item)
        common = set(self._queues[0]).intersection(*self._queues[1:])
        return [self._take([s] * self.n_inputs) for s in sorted(common)]


class PythonApproximateTimePolicy(_StampQueues[T]):
    """The first set within ``slop_ns`` of each new item, as the Python ``ApproximateTimeSynchronizer``.

    Each input keeps its last ``queue_size`` stamps. When an item arrives, every
    other input's stamps within ``slop_ns`` of it are ranked by their distance to
    it, and the first combination (closest first, in input order) whose whole
    span (newest minus oldest stamp) is within ``slop_ns`` is output at once and
    removed from the queues. So a set goes out as soon as it exists, items may
    arrive in any order, and each item is used at most once.

    Parameters
    ----------
    n_inputs
        Number of inputs (two or more).
    queue_size
        Stamps kept per input.
    slop_ns
        The widest span a set may have, in nanoseconds.
    """

    def __init__(self, n_inputs: int, queue_size: int, slop_ns: int) -> None:
        super().__init__(n_inputs, queue_size)
        self.slop_ns = _check_ns("slop_ns", slop_ns)

    def __repr__(self) -> str:
        return (
            f"<PythonApproximateTimePolicy inputs={self.n_inputs} queue_size={self.queue_size} "
            f"slop_ns={self.slop_ns}>"
        )

    def add(self, index: int, stamp_ns: int, item: T) -> list[tuple[T, ...]]:
        """Add ``item`` (stamped ``stamp_ns``) on input ``index``; return the set it completed, if any."""
        self._insert(index, stamp_ns, item)
        if stamp_ns not in self._queues[index]:
            return []  # older than everything in a full queue: already dropped
        slop = self.slop_ns
        candidates: list[list[int]] = []
        for i, q in enumerate(self._queues):
            if i == index:
                continue
            near = sorted((s for s in q if abs(s - stamp_ns) <= slop), key=lambda s: abs(s - stamp_ns))
            if not near:
                return []
            candidates.append(near)
        for combo in itertools.product(*candidates):
            stamps = list(combo)
            stamps.insert(index, stamp_ns)
            if max(stamps) - min(stamps) <= slop:
                return [self._take(stamps)]
        return []


class ApproximateEpsilonTimePolicy(Generic[T]):
    """Sets whose stamps all lie within ``epsilon_ns`` of the oldest head (C++ ``ApproximateEpsilonTime``).

    Each input keeps a FIFO queue. Once every input holds an item, the oldest
    head stamp is found; when every head is within ``epsilon_ns`` after it the
    heads are output together, otherwise the heads that are (the oldest one
    among them) are dropped as unmatched and the search goes on. An input that
    holds more than ``queue_size`` items while another input is empty drops
    its oldest.

    Parameters
    ----------
    n_inputs
        Number of inputs (two or more).
    queue_size
        Items kept per input while waiting for the others.
    epsilon_ns
        How far after the oldest head another head may be, in nanoseconds.
    """

    def __init__(self, n_inputs: int, queue_size: int, epsilon_ns: int) -> None:
        _check_inputs(n_inputs, queue_size, allow_zero_queue=False)
        self.n_inputs = n_inputs
        self.queue_size = queue_size
        self.epsilon_ns = _check_ns("epsilon_ns", epsilon_ns)
        self._queues: list[deque[tuple[int, T]]] = [deque() for _ in range(n_inputs)]
        self.dropped = 0

    def __repr__(self) -> str:
        return (
            f"<ApproximateEpsilonTimePolicy inputs={self.n_inputs} queue_size={self.queue_size} "
            f"epsilon_ns={self.epsilon_ns}>"
        )

    def queued(self, index: int) -> int:
        _check_index(index, self.n_inputs)
        return len(self._queues[index])

    def clear(self) -> None:
        for q in self._queues:
            q.clear()

    def add(self, index: int, stamp_ns: int, item: T) -> list[tuple[T, ...]]:
        """Add ``item`` (stamped ``stamp_ns``) on input ``index``; return the sets it lets us output."""
        _check_index(index, self.n_inputs)
        q = self._queues[index]
        q.append((stamp_ns, item))
        out: list[tuple[T, ...]] = []
        if all(self._queues):
            while all(self._queues):
                heads = [qq[0][0] for qq in self._queues]
                oldest = min(heads)
                limit = oldest + self.epsilon_ns
                if all(h <= limit for h in heads):
                    out.append(tuple(qq.popleft()[1] for qq in self._queues))
                else:
                    for qq in self._queues:
                        if qq[0][0] <= limit:
                            qq.popleft()
                            self.dropped += 1
        elif len(q) > self.queue_size:
            q.popleft()
            self.dropped += 1
        return out
