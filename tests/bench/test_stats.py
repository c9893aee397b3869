"""The benchmark's statistics are exact on known samples."""

from __future__ import annotations

import math

import numpy as np
import pytest

from aiorobot.bench._stats import (
    latency_stats,
    median_of_results,
    percentile,
    period_stats,
    periods_from_stamps,
)


def test_percentile_interpolates_between_closest_ranks() -> None:
    samples = [15.0, 20.0, 35.0, 40.0, 50.0]
    assert percentile(samples, 0) == 15.0
    assert percentile(samples, 50) == 35.0
    assert percentile(samples, 100) == 50.0
    assert percentile(samples, 40) == pytest.approx(29.0)  # rank 1.6: 20 + 0.6 * 15
    assert percentile(samples, 99) == pytest.approx(49.6)  # rank 3.96: 40 + 0.96 * 10


def test_percentile_matches_numpy_linear_on_random_samples() -> None:
    rng = np.random.default_rng(7)
    samples = rng.exponential(3.0, size=257).tolist()
    for q in (0, 1, 25, 50, 75, 99, 99.9, 100):
        assert percentile(samples, q) == pytest.approx(float(np.percentile(samples, q)), rel=1e-12)


def test_percentile_does_not_care_about_input_order() -> None:
    assert percentile([3.0, 1.0, 2.0], 50) == 2.0


def test_percentile_rejects_empty_samples_and_bad_q() -> None:
    with pytest.raises(ValueError, match=r"^percentile of no samples"):
        percentile([], 50)
    with pytest.raises(ValueError, match=r"within \[0, 100\], received 101"):
        percentile([1.0], 101)


def test_periods_from_stamps_gives_milliseconds_and_drops_warmup() -> None:
    stamps = [0.0, 0.020, 0.041, 0.060, 0.230]
    assert periods_from_stamps(stamps) == pytest.approx([20.0, 21.0, 19.0, 170.0])
    assert periods_from_stamps(stamps, warmup=2) == pytest.approx([19.0, 170.0])
    assert periods_from_stamps([1.0]) == []


def test_period_stats_on_known_periods() -> None:
    periods = [20.0, 20.0, 21.5, 19.0, 26.0, 20.5]
    s = period_stats(periods, nominal_ms=20.0)
    assert s.samples == 6
    assert s.mean_ms == pytest.approx(127.0 / 6)
    mean = 127.0 / 6
    assert s.stdev_ms == pytest.approx(math.sqrt(sum((p - mean) ** 2 for p in periods) / 5))
    assert s.min_ms == 19.0
    assert s.max_ms == 26.0
    assert s.p50_ms == pytest.approx(20.25)
    assert s.p99_ms == pytest.approx(float(np.percentile(periods, 99)))
    assert s.late_1ms == 2  # 21.5 and 26.0; 20.5 is within 1 ms
    assert s.late_5ms == 1  # 26.0


def test_period_stats_counts_a_period_exactly_at_the_bound_as_on_time() -> None:
    s = period_stats([21.0, 25.0], nominal_ms=20.0)
    assert (s.late_1ms, s.late_5ms) == (1, 0)


def test_period_stats_of_one_sample_has_zero_stdev() -> None:
    s = period_stats([20.0], nominal_ms=20.0)
    assert s.stdev_ms == 0.0 and s.p99_ms == 20.0


def test_period_stats_needs_samples() -> None:
    with pytest.raises(ValueError, match="at least one period"):
        period_stats([], nominal_ms=20.0)


def test_latency_stats_on_known_latencies() -> None:
    s = latency_stats([1.0, 2.0, 3.0, 4.0, 100.0])
    assert s.as_dict() == {"samples": 5, "mean_us": 22.0, "p50_us": 3.0, "p99_us": pytest.approx(96.16), "max_us": 100.0}


def test_median_of_results_takes_medians_and_concatenates_samples() -> None:
    runs = [
        {"stats": {"max_ms": 30.0, "late": 3}, "periods_ms": [1.0, 2.0], "name": "a", "rows": [{"x": 1}]},
        {"stats": {"max_ms": 10.0, "late": 1}, "periods_ms": [3.0], "name": "b", "rows": [{"x": 5}]},
        {"stats": {"max_ms": 20.0, "late": 2}, "periods_ms": [], "name": "c", "rows": [{"x": 3}]},
    ]
    merged = median_of_results(runs)
    assert merged == {
        "stats": {"max_ms": 20.0, "late": 2},
        "periods_ms": [1.0, 2.0, 3.0],
        "name": "a",
        "rows": [{"x": 3}],
    }


def test_median_of_results_of_an_even_count_averages_the_middle_two() -> None:
    assert median_of_results([{"v": 1}, {"v": 2}]) == {"v": 1.5}
    assert median_of_results([{"v": 1}, {"v": 3}]) == {"v": 2}


def test_median_of_results_refuses_repeats_of_different_shapes() -> None:
    with pytest.raises(ValueError, match="repeats differ in shape"):
        median_of_results([{"a": 1}, {"b": 1}])
