"""Pure statistics for the benchmark: percentiles, period and latency figures, medians of repeats.

Nothing here touches a clock or a runtime: every function takes plain numbers and
returns plain numbers, so the tests can check them exactly on known samples.
"""

from __future__ import annotations

import math
import statistics
from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass
from typing import Any

__all__ = [
    "LatencyStats",
    "PeriodStats",
    "latency_stats",
    "median_of_results",
    "percentile",
    "periods_from_stamps",
    "period_stats",
]


def percentile(samples: Sequence[float], q: float) -> float:
    """The ``q``-th percentile by linear interpolation between closest ranks.

    The same definition as ``numpy.percentile(samples, q)`` (method "linear"):
    the value at rank ``(n - 1) * q / 100`` of the sorted samples, interpolated.

    Parameters
    ----------
    samples : sequence of float, shape (n,), n >= 1
    q : float in [0, 100]
    """
    if not samples:
        raise ValueError("percentile of no samples: expected at least one sample, received an empty sequence")
    if not 0.0 <= q <= 100.0:
        raise ValueError(f"percentile q must be within [0, 100], received {q!r}")
    ordered = sorted(float(s) for s in samples)
    rank = (len(ordered) - 1) * q / 100.0
    low = math.floor(rank)
    high = min(low + 1, len(ordered) - 1)
    frac = rank - low
    return ordered[low] + (ordered[high] - ordered[low]) * frac


def periods_from_stamps(stamps_sec: Sequence[float], warmup: int = 0) -> list[float]:
    """Periods in milliseconds between successive callback start stamps.

    Parameters
    ----------
    stamps_sec : sequence of float, shape (n,)
        Monotonic start times of successive callbacks, in seconds.
    warmup : int
        How many leading periods to drop (they include start-up effects).

    Returns
    -------
    list of float, shape (max(n - 1 - warmup, 0),)
    """
    if warmup < 0:
        raise ValueError(f"warmup must be >= 0, received {warmup!r}")
    periods = [(b - a) * 1e3 for a, b in zip(stamps_sec, stamps_sec[1:])]
    return periods[warmup:]


@dataclass(frozen=True, slots=True)
class PeriodStats:
    """Figures of a periodic callback's measured periods, all in milliseconds.

    ``late_1ms`` and ``late_5ms`` count periods longer than the nominal period by
    more than 1 ms and 5 ms.
    """

    nominal_ms: float
    samples: int
    mean_ms: float
    stdev_ms: float
    min_ms: float
    p50_ms: float
    p99_ms: float
    max_ms: float
    late_1ms: int
    late_5ms: int

    def as_dict(self) -> dict[str, Any]:
        return asdict(self)


def period_stats(periods_ms: Sequence[float], nominal_ms: float) -> PeriodStats:
    """Summarise measured periods against the nominal one.

    ``stdev_ms`` is the sample standard deviation (n - 1 in the denominator); it
    is 0.0 for a single sample.

    Parameters
    ----------
    periods_ms : sequence of float, shape (n,), n >= 1
    nominal_ms : float
        The period the callback was asked to keep.
    """
    if not periods_ms:
        raise ValueError("period_stats needs at least one period, received none; run more control periods")
    values = [float(p) for p in periods_ms]
    return PeriodStats(
        nominal_ms=float(nominal_ms),
        samples=len(values),
        mean_ms=statistics.fmean(values),
        stdev_ms=statistics.stdev(values) if len(values) > 1 else 0.0,
        min_ms=min(values),
        p50_ms=percentile(values, 50),
        p99_ms=percentile(values, 99),
        max_ms=max(values),
        late_1ms=sum(1 for p in values if p > nominal_ms + 1.0),
        late_5ms=sum(1 for p in values if p > nominal_ms + 5.0),
    )


@dataclass(frozen=True, slots=True)
class LatencyStats:
    """Figures of a latency sample set, all in microseconds."""

    samples: int
    mean_us: float
    p50_us: float
    p99_us: float
    max_us: float

    def as_dict(self) -> dict[str, Any]:
        return asdict(self)


def latency_stats(latencies_us: Sequence[float]) -> LatencyStats:
    """Summarise latencies (or absolute period errors) given in microseconds.

    Parameters
    ----------
    latencies_us : sequence of float, shape (n,), n >= 1
    """
    if not latencies_us:
        raise ValueError("latency_stats needs at least one sample, received none")
    values = [float(v) for v in latencies_us]
    return LatencyStats(
        samples=len(values),
        mean_us=statistics.fmean(values),
        p50_us=percentile(values, 50),
        p99_us=percentile(values, 99),
        max_us=max(values),
    )


def median_of_results(results: Sequence[Any]) -> Any:
    """Merge the results of repeated runs: the median of every number.

    The results must share one shape (nested dicts and lists of the same keys).
    Numbers (ints and floats, not bools) become the median across repeats;
    lists of numbers (raw samples) are concatenated, so a plot shows every
    repeat; other lists are merged element-wise; anything else (strings, bools,
    None) keeps the first repeat's value.

    Examples
    --------
    >>> median_of_results([{"a": 1, "s": [1.0]}, {"a": 3, "s": [2.0]}, {"a": 2, "s": [3.0]}])
    {'a': 2, 's': [1.0, 2.0, 3.0]}
    """
    if not results:
        raise ValueError("median_of_results needs at least one result, received none")
    first = results[0]
    if len(results) == 1:
        return first
    if isinstance(first, Mapping):
        keys = list(first)
        for other in results[1:]:
            if not isinstance(other, Mapping) or list(other) != keys:
                raise ValueError(
                    f"repeats differ in shape: expected keys {keys!r}, received "
                    f"{list(other) if isinstance(other, Mapping) else type(other).__name__!r}"
                )
        return {k: median_of_results([r[k] for r in results]) for k in keys}
    if _is_number(first):
        values = [r for r in results if _is_number(r)]
        if len(values) != len(results):
            return first
        med = statistics.median(values)
        if all(isinstance(v, int) for v in values) and float(med).is_integer():
            return int(med)
        return float(med)
    if isinstance(first, list):
        if all(isinstance(r, list) and all(_is_number(v) for v in r) for r in results):
            return [v for r in results for v in r]
        if all(isinstance(r, list) and len(r) == len(first) for r in results):
            return [median_of_results([r[i] for r in results]) for i in range(len(first))]
        return first
    return first


def _is_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)
