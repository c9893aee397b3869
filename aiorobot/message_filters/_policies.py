"""Synchronisation policies: which messages of N inputs belong together. Pure, no runtime.

Both policies are ports of ROS 2's ``message_filters`` C++ sync policies
(``sync_policies/exact_time.hpp`` and ``sync_policies/approximate_time.hpp``);
stamps are integer nanoseconds and items are opaque (messages, in practice).
``add(index, stamp_ns, item)`` returns the sets that became complete, each a
tuple with one item per input, in input order. The synchronizer filters wrap
these with subscriptions and callbacks.
"""

from __future__ import annotations

import logging
from collections import deque
from collections.abc import Sequence
from typing import Any, Generic, TypeVar

__all__ = ["ApproximateTimePolicy", "ExactTimePolicy"]

T = TypeVar("T")

_log = logging.getLogger("aiorobot.message_filters")

#: The largest interval the C++ policy accepts by default (``Duration(INT32_MAX, 999999999)``).
_UNBOUNDED_NS = (2**31 - 1) * 1_000_000_000 + 999_999_999


def _check_inputs(n_inputs: int, queue_size: int, *, allow_zero_queue: bool) -> None:
    if isinstance(n_inputs, bool) or not isinstance(n_inputs, int) or n_inputs < 2:
        raise ValueError(f"a synchronizer needs two or more inputs, got {n_inputs!r}")
    low = 0 if allow_zero_queue else 1
    if isinstance(queue_size, bool) or not isinstance(queue_size, int) or queue_size < low:
        raise ValueError(f"queue_size: expected an int >= {low}, got {queue_size!r}")


class _Missing:
    __slots__ = ()

    def __repr__(self) -> str:
        return "<missing>"


_MISSING: Any = _Missing()


class ExactTimePolicy(Generic[T]):
    """Sets of items whose stamps are exactly equal (ROS 2's ``ExactTime`` policy).

    Items wait in sets keyed by stamp. When a set is complete it is output, and
    every older incomplete set is dropped (inputs are assumed to arrive in stamp
    order). When more than ``queue_size`` sets are pending the oldest are
    dropped; ``queue_size=0`` keeps every pending set. A second item with the
    same stamp on the same input replaces the first.

    Parameters
    ----------
    n_inputs
        Number of inputs (two or more).
    queue_size
        How many incomplete sets to keep.
    """

    def __init__(self, n_inputs: int, queue_size: int) -> None:
        _check_inputs(n_inputs, queue_size, allow_zero_queue=True)
        self.n_inputs = n_inputs
        self.queue_size = queue_size
        self._sets: dict[int, list[Any]] = {}
        self.dropped_sets = 0

    def __repr__(self) -> str:
        return f"<ExactTimePolicy inputs={self.n_inputs} queue_size={self.queue_size} pending={len(self._sets)}>"

    @property
    def pending(self) -> int:
        """How many incomplete sets wait for their other items."""
        return len(self._sets)

    def add(self, index: int, stamp_ns: int, item: T) -> list[tuple[T, ...]]:
        """Add ``item`` (stamped ``stamp_ns``) on input ``index``; return the sets completed by it."""
        _check_index(index, self.n_inputs)
        entry = self._sets.get(stamp_ns)
        if entry is None:
            entry = self._sets[stamp_ns] = [_MISSING] * self.n_inputs
        entry[index] = item
        out: list[tuple[T, ...]] = []
        if all(x is not _MISSING for x in entry):
            out.append(tuple(entry))
            del self._sets[stamp_ns]
            older = [s for s in self._sets if s <= stamp_ns]
            for s in older:
                del self._sets[s]
            self.dropped_sets += len(older)
        if self.queue_size > 0 and len(self._sets) > self.queue_size:
            excess = sorted(self._sets)[: len(self._sets) - self.queue_size]
            for s in excess:
                del self._sets[s]
            self.dropped_sets += len(excess)
        return out

    def clear(self) -> None:
        self._sets.clear()


class ApproximateTimePolicy(Generic[T]):
    """Best-matching sets of items with nearby stamps (ROS 2's ``ApproximateTime`` policy).

    A port of the adaptive algorithm of ``message_filters``' C++
    ``sync_policies::ApproximateTime``: it outputs a set as soon as it can
    prove that no later message could give a set with a smaller time span
    (the span of a set is its newest stamp minus its oldest), so it waits for
    at least one newer message on the inputs before deciding. Every item is
    used at most once; items older than an output set are dropped; when an
    input holds more than ``queue_size`` items its oldest is dropped.

    Parameters
    ----------
    n_inputs
        Number of inputs (two or more).
    queue_size
        Items kept per input (the C++ ``queue_size``); at least 2 is recommended.
    max_interval_ns
        Sets whose span exceeds this are never output (the C++
        ``setMaxIntervalDuration``; the synchronizer's ``slop_sec``). ``None``: unbounded.
    age_penalty
        How much a newer candidate set must improve on the current one to
        replace it (``>= 0``, default 0.1 as in ROS 2).
    inter_message_lower_bounds_ns
        Per input, the least time between two of its messages when known
        (``setInterMessageLowerBound``); lets the policy output sets earlier.
    """

    def __init__(
        self,
        n_inputs: int,
        queue_size: int,
        *,
        max_interval_ns: int | None = None,
        age_penalty: float = 0.1,
        inter_message_lower_bounds_ns: Sequence[int] | None = None,
    ) -> None:
        _check_inputs(n_inputs, queue_size, allow_zero_queue=False)
        if max_interval_ns is not None and (not isinstance(max_interval_ns, int) or max_interval_ns < 0):
            raise ValueError(f"max_interval_ns: expected an int >= 0 or None, got {max_interval_ns!r}")
        if not age_penalty >= 0:
            raise ValueError(f"age_penalty: expected >= 0, got {age_penalty!r}")
        bounds = list(inter_message_lower_bounds_ns) if inter_message_lower_bounds_ns is not None else [0] * n_inputs
        if len(bounds) != n_inputs or any(not isinstance(b, int) or b < 0 for b in bounds):
            raise ValueError(
                f"inter_message_lower_bounds_ns: expected {n_inputs} ints >= 0, got {inter_message_lower_bounds_ns!r}"
            )
        self.n_inputs = n_inputs
        self.queue_size = queue_size
        self.max_interval_ns = _UNBOUNDED_NS if max_interval_ns is None else max_interval_ns
        self.age_penalty = float(age_penalty)
        self._lower_bounds = bounds
        self._deques: list[deque[tuple[int, T]]] = [deque() for _ in range(n_inputs)]
        self._past: list[list[tuple[int, T]]] = [[] for _ in range(n_inputs)]
        self._num_non_empty = 0
        self._candidate: tuple[tuple[int, T], ...] | None = None
        self._candidate_start = 0
        self._candidate_end = 0
        self._pivot: int | None = None
        self._pivot_time = 0
        self._has_dropped = [False] * n_inputs
        self._warned = [False] * n_inputs
        self.dropped = 0

    def __repr__(self) -> str:
        queued = [len(d) + len(p) for d, p in zip(self._deques, self._past)]
        return f"<ApproximateTimePolicy inputs={self.n_inputs} queue_size={self.queue_size} queued={queued}>"

    def queued(self, index: int) -> int:
        """How many items input ``index`` holds (waiting or part of the current candidate)."""
        _check_index(index, self.n_inputs)
        return len(self._deques[index]) + len(self._past[index])

    def set_inter_message_lower_bound(self, index: int, lower_bound_ns: int) -> None:
        _check_index(index, self.n_inputs)
        if not isinstance(lower_bound_ns, int) or lower_bound_ns < 0:
            raise ValueError(f"lower_bound_ns: expected an int >= 0, got {lower_bound_ns!r}")
        self._lower_bounds[index] = lower_bound_ns

    # -- input ------------------------------------------------------------------

    def add(self, index: int, stamp_ns: int, item: T) -> list[tuple[T, ...]]:
        """Add ``item`` (stamped ``stamp_ns``) on input ``index``; return the sets it lets us output."""
        _check_index(index, self.n_inputs)
        out: list[tuple[T, ...]] = []
        dq = self._deques[index]
        dq.append((stamp_ns, item))
        if len(dq) == 1:
            self._num_non_empty += 1
            if self._num_non_empty == self.n_inputs:
                self._process(out)
        else:
            self._check_inter_message_bound(index)
        # During _process the queue may hold queue_size + 1 items.
        if len(dq) + len(self._past[index]) > self.queue_size:
            self._num_non_empty = 0  # recomputed by _recover_all
            self._recover_all()
            dq.popleft()
            self.dropped += 1
            self._has_dropped[index] = True
            if self._pivot is not None:
                self._candidate = None
                self._pivot = None
                self._process(out)
        return out

    def clear(self) -> None:
        for dq, past in zip(self._deques, self._past):
            dq.clear()
            past.clear()
        self._num_non_empty = 0
        self._candidate = None
        self._pivot = None

    # -- the algorithm (names follow approximate_time.hpp) ------------------------

    def _check_inter_message_bound(self, i: int) -> None:
        if self._warned[i]:
            return
        dq = self._deques[i]
        msg_time = dq[-1][0]
        if len(dq) == 1:
            if not self._past[i]:
                return
            previous = self._past[i][-1][0]
        else:
            previous = dq[-2][0]
        if msg_time < previous:
            _log.warning("approximate time sync: messages of input %d arrived out of order (warning once)", i)
            self._warned[i] = True
        elif msg_time - previous < self._lower_bounds[i]:
            _log.warning(
                "approximate time sync: messages of input %d arrived %d ns apart, closer than the lower bound "
                "%d ns you gave (warning once)",
                i,
                msg_time - previous,
                self._lower_bounds[i],
            )
            self._warned[i] = True

    def _penalised(self, delta_ns: int) -> int:
        return int(delta_ns * (1.0 + self.age_penalty))

    def _delete_front(self, i: int) -> None:
        dq = self._deques[i]
        dq.popleft()
        if not dq:
            self._num_non_empty -= 1

    def _move_front_to_past(self, i: int) -> None:
        dq = self._deques[i]
        self._past[i].append(dq.popleft())
        if not dq:
            self._num_non_empty -= 1

    def _make_candidate(self) -> None:
        self._candidate = tuple(dq[0] for dq in self._deques)
        for past in self._past:
            past.clear()

    def _recover(self, i: int, count: int | None = None) -> None:
        past = self._past[i]
        dq = self._deques[i]
        n = len(past) if count is None else count
        for _ in range(n):
            dq.appendleft(past.pop())
        if dq:
            self._num_non_empty += 1

    def _recover_all(self) -> None:
        for i in range(self.n_inputs):
            self._recover(i)

    def _publish_candidate(self, out: list[tuple[T, ...]]) -> None:
        assert self._candidate is not None
        out.append(tuple(item for _, item in self._candidate))
        self._candidate = None
        self._pivot = None
        self._num_non_empty = 0
        for i in range(self.n_inputs):
            past = self._past[i]
            dq = self._deques[i]
            while past:
                dq.appendleft(past.pop())
            dq.popleft()  # the item that went out
            if dq:
                self._num_non_empty += 1

    def _boundary(self, times: Sequence[int], end: bool) -> tuple[int, int]:
        """The earliest (``end=False``: first of ties) or latest (``end=True``: last of ties) time."""
        index, time = 0, times[0]
        for i in range(1, len(times)):
            if (times[i] < time) ^ end:
                index, time = i, times[i]
        return index, time

    def _virtual_times(self) -> list[int]:
        times = []
        for i in range(self.n_inputs):
            dq = self._deques[i]
            if dq:
                times.append(dq[0][0])
            else:
                bound = self._past[i][-1][0] + self._lower_bounds[i]
                times.append(max(bound, self._pivot_time))
        return times

    def _process(self, out: list[tuple[T, ...]]) -> None:
        n = self.n_inputs
        while self._num_non_empty == n:
            heads = [dq[0][0] for dq in self._deques]
            end_index, end_time = self._boundary(heads, end=True)
            start_index, start_time = self._boundary(heads, end=False)
            for i in range(n):
                if i != end_index:
                    # No dropped message could have been better than the ones we have.
                    self._has_dropped[i] = False
            if self._pivot is None:
                if end_time - start_time > self.max_interval_ns:
                    self._delete_front(start_index)  # too wide to ever be a candidate
                    continue
                if self._has_dropped[end_index]:
                    self._delete_front(start_index)  # not a good pivot
                    continue
                self._make_candidate()
                self._candidate_start, self._candidate_end = start_time, end_time
                self._pivot, self._pivot_time = end_index, end_time
                self._move_front_to_past(start_index)
            else:
                if self._penalised(end_time - self._candidate_end) >= start_time - self._candidate_start:
                    self._move_front_to_past(start_index)  # not better
                else:
                    self._make_candidate()  # better; same pivot
                    self._candidate_start, self._candidate_end = start_time, end_time
                    self._move_front_to_past(start_index)
            if start_index == self._pivot:
                # Every candidate for this pivot has been seen: output the best.
                self._publish_candidate(out)
            elif self._penalised(end_time - self._candidate_end) >= self._pivot_time - self._candidate_start:
                # Any later candidate spans [pivot_time, end_time], already too wide.
                self._publish_candidate(out)
            elif self._num_non_empty < n:
                self._virtual_search(out)

    def _virtual_search(self, out: list[tuple[T, ...]]) -> None:
        """Use the inputs' rate bounds to try to prove the candidate optimal now."""
        moves = [0] * self.n_inputs
        while True:
            times = self._virtual_times()
            _, end_time = self._boundary(times, end=True)
            start_index, start_time = self._boundary(times, end=False)
            grown = self._penalised(end_time - self._candidate_end)
            if grown >= self._pivot_time - self._candidate_start:
                self._publish_candidate(out)  # proved optimal; undoes the virtual moves too
                return
            if grown < start_time - self._candidate_start:
                # An optimistic future candidate would be better: cannot prove it yet.
                self._num_non_empty = 0
                for i in range(self.n_inputs):
                    self._recover(i, moves[i])
                return
            self._move_front_to_past(start_index)
            moves[start_index] += 1


def _check_index(index: int, n_inputs: int) -> None:
    if not 0 <= index < n_inputs:
        raise IndexError(f"input index: expected 0..{n_inputs - 1}, got {index!r}")
