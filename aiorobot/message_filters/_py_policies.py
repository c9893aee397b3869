"""The Python ``message_filters`` policies, and the C++ ``ApproximateEpsilonTime``. Pure, no runtime.

ROS 2's Python ``message_filters`` package (what rclpy users and the tutorials
use) matches messages differently from the C++ policies in :mod:`._policies`:
every input keeps a stamp-keyed queue, and a set is delivered as soon as one
exists, without waiting for a newer message; out-of-order input is fine.
:class:`PythonExactTimePolicy` and :class:`PythonApproximateTimePolicy` port
that behaviour; :class:`ApproximateEpsilonTimePolicy` ports the C++
``sync_policies::ApproximateEpsilonTime`` and :class:`LatestTimePolicy` the C++
``sync_policies::LatestTime``. Like the C++ ports, ``add(index,
stamp_ns, item)`` returns the sets the item completed, each a tuple with one
item per input in input order.
"""

from __future__ import annotations

import itertools
from collections import deque
from collections.abc import Sequence
from typing import Any, Generic, TypeVar

from ._policies import _check_index, _check_inputs

__all__ = [
    "ApproximateEpsilonTimePolicy",
    "LatestTimePolicy",
    "PythonApproximateTimePolicy",
    "PythonExactTimePolicy",
]

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


class _Rate:
    """One input's arrival rate, as the C++ ``LatestTime::Rate`` estimates it (EMA with step detection)."""

    __slots__ = ("do_error_init", "do_hz_init", "error", "error_alpha", "hz", "margin", "prev_ns", "rate_alpha")

    def __init__(self, start_ns: int, rate_alpha: float, error_alpha: float, margin: float) -> None:
        self.prev_ns = start_ns
        self.hz = 0.0
        self.error = 0.0
        self.rate_alpha = rate_alpha
        self.error_alpha = error_alpha
        self.margin = margin
        self.do_hz_init = True
        self.do_error_init = True

    def compute_hz(self, now_ns: int) -> bool:
        step_change = True
        while step_change:
            step_change = False
            period = (now_ns - self.prev_ns) / 1e9
            if period <= 0.0:
                return False
            if self.do_hz_init:
                self.hz = 1.0 / period
                self.do_hz_init = False
                continue
            if self.do_error_init:
                self.error = abs(self.hz - 1.0 / period)
                self.do_error_init = False
            else:
                if abs(self.hz - 1.0 / period) > self.margin * self.error:
                    self.do_hz_init = True  # a step change of rate: start the estimate again
                    self.do_error_init = True
                    step_change = True
                    continue
                self.error = self.error_alpha * abs(self.hz - 1.0 / period) + (1.0 - self.error_alpha) * self.error
            self.hz = self.rate_alpha / period + (1.0 - self.rate_alpha) * self.hz
        self.prev_ns = now_ns
        return True


#: The C++ ``LatestTime`` defaults: rate EMA alpha, error EMA alpha, step-change margin factor.
DEFAULT_RATE_CONFIG = (0.9, 0.3, 10.0)


class LatestTimePolicy(Generic[T]):
    """The latest item of every input, output whenever the fastest input delivers (C++ ``LatestTime``).

    Slower inputs are repeated (zero-order hold) at the rate of the fastest until
    they deliver again. Rates are estimated from *arrival* times on ``now_ns``
    (the synchronizer's node clock by default, so sim time works); stamps are not
    used, so headerless messages are fine. An input that falls silent for much
    longer than its rate promised stops being the pivot, and the next fastest
    takes over. Nothing is output until every input has delivered once.

    Parameters
    ----------
    n_inputs
        Number of inputs (two or more).
    now_ns
        The clock, in integer nanoseconds (``None``: set by the synchronizer).
    rate_configs
        ``(rate_ema_alpha, error_ema_alpha, rate_step_change_margin_factor)``, one
        for all inputs or one per input (the C++ ``setRateConfig`` /
        ``setRateConfigPerMessage``).
    """

    needs_stamps = False

    def __init__(
        self,
        n_inputs: int,
        *,
        now_ns: Any = None,
        rate_configs: Sequence[tuple[float, float, float]] | None = None,
    ) -> None:
        _check_inputs(n_inputs, 1, allow_zero_queue=False)
        configs = list(rate_configs) if rate_configs is not None else [DEFAULT_RATE_CONFIG]
        if len(configs) not in (1, n_inputs) or any(len(c) != 3 for c in configs):
            raise ValueError(
                f"rate_configs: expected one (rate_ema_alpha, error_ema_alpha, margin_factor) triple or "
                f"{n_inputs}, got {rate_configs!r}"
            )
        self.n_inputs = n_inputs
        self.now_ns = now_ns
        self._configs = configs if len(configs) == n_inputs else configs * n_inputs
        self._latest: list[Any] = [_UNSET] * n_inputs
        self._rates: list[_Rate | None] = [None] * n_inputs

    def __repr__(self) -> str:
        rates = ", ".join(f"{r.hz:.3g}" if r is not None else "-" for r in self._rates)
        return f"<LatestTimePolicy inputs={self.n_inputs} hz=[{rates}]>"

    def rate_hz(self, index: int) -> float:
        """The estimated arrival rate of input ``index`` (0 until it has delivered twice)."""
        _check_index(index, self.n_inputs)
        rate = self._rates[index]
        return rate.hz if rate is not None else 0.0

    def clear(self) -> None:
        self._latest = [_UNSET] * self.n_inputs
        self._rates = [None] * self.n_inputs

    def add(self, index: int, stamp_ns: int, item: T) -> list[tuple[T, ...]]:
        """Add ``item`` on input ``index`` (``stamp_ns`` is ignored); return the set it triggers, if any."""
        _check_index(index, self.n_inputs)
        if self.now_ns is None:
            raise RuntimeError("LatestTimePolicy needs a clock: pass now_ns=, or use it in a Synchronizer")
        now = int(self.now_ns())
        if self._rates[index] is None:
            self._rates[index] = _Rate(now, *self._configs[index])
            self._latest[index] = item
            return []
        self._latest[index] = item
        valid = self._rates[index].compute_hz(now)  # type: ignore[union-attr]
        if valid and index == self._pivot(now) and all(x is not _UNSET for x in self._latest):
            return [tuple(self._latest)]
        return []

    def _pivot(self, now_ns: int) -> int:
        """The fastest input that is not late (C++ ``find_pivot``); ``n_inputs`` when none."""
        known = [i for i, r in enumerate(self._rates) if r is not None]
        known.sort(key=lambda i: -self._rates[i].hz)  # type: ignore[union-attr]  # stable: ties keep input order
        for i in known:
            rate = self._rates[i]
            assert rate is not None
            period = (now_ns - rate.prev_ns) / 1e9
            if period == 0.0:
                if rate.hz > 0.0:
                    return i
                continue
            if not rate.do_error_init and rate.hz - 1.0 / period > rate.margin * rate.error:
                continue  # late: slower than its rate promised
            if rate.hz > 0.0:
                return i
        return self.n_inputs


class _Unset:
    __slots__ = ()

    def __repr__(self) -> str:
        return "<unset>"


_UNSET: Any = _Unset()
