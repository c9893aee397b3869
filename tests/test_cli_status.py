"""The bundled example's statistics core and the status display of ``aiorobot run``."""

from __future__ import annotations

import io
import math

import pytest

from aiorobot.cli._status import StatusDisplay
from aiorobot.examples.stats import TopicStatistics

MS = 1_000_000


def test_empty_statistics_report_nan_rate_and_latency() -> None:
    s = TopicStatistics().total()
    assert s.count == 0
    assert math.isnan(s.rate_hz) and math.isnan(s.latency_p50_us) and math.isnan(s.latency_max_us)


def test_rate_is_messages_per_second_between_first_and_last() -> None:
    stats = TopicStatistics()
    for i in range(51):  # 50 intervals of 20 ms
        stats.record(receive_ns=i * 20 * MS, latency_ns=100_000)
    total = stats.total()
    assert total.count == 51
    assert total.rate_hz == pytest.approx(50.0)


def test_recent_rate_only_counts_the_window() -> None:
    stats = TopicStatistics(window_sec=1.0)
    for i in range(100):  # 10 Hz for 10 s ...
        stats.record(receive_ns=i * 100 * MS, latency_ns=0)
    for i in range(1, 101):  # ... then 100 Hz for 1 s
        stats.record(receive_ns=9_900 * MS + i * 10 * MS, latency_ns=0)
    now_ns = 10_900 * MS
    assert stats.recent(now_ns).rate_hz == pytest.approx(100.0)
    assert stats.total().count == 200


def test_recent_rate_is_nan_after_the_stream_stops() -> None:
    stats = TopicStatistics(window_sec=1.0)
    for i in range(10):
        stats.record(receive_ns=i * 10 * MS, latency_ns=0)
    assert math.isnan(stats.recent(now_ns=5_000 * MS).rate_hz)


def test_latency_percentiles_and_max_in_microseconds() -> None:
    stats = TopicStatistics(max_samples=1000)
    for i in range(1, 101):  # 1..100 us
        stats.record(receive_ns=i * MS, latency_ns=i * 1000)
    total = stats.total()
    assert total.latency_p50_us == pytest.approx(50.0, abs=1.0)
    assert total.latency_p99_us == pytest.approx(99.0, abs=1.0)
    assert total.latency_max_us == 100.0


def test_latency_percentiles_use_recent_samples_but_max_is_all_time() -> None:
    stats = TopicStatistics(max_samples=10)
    stats.record(receive_ns=0, latency_ns=5_000_000)
    for i in range(1, 11):
        stats.record(receive_ns=i * MS, latency_ns=1000)
    total = stats.total()
    assert total.latency_p99_us == 1.0
    assert total.latency_max_us == 5000.0


@pytest.mark.parametrize(("window_sec", "max_samples"), [(0.0, 10), (1.0, 0)])
def test_statistics_reject_bad_settings(window_sec: float, max_samples: int) -> None:
    with pytest.raises(ValueError, match=r"^expected window_sec > 0 and max_samples >= 1, found"):
        TopicStatistics(window_sec=window_sec, max_samples=max_samples)


class _Reporter:
    def __init__(self, name: str) -> None:
        self.name = name

    def get_name(self) -> str:
        return self.name

    def status_line(self) -> str:
        return f"{self.name}: ok"

    def summary(self) -> str:
        return f"{self.name}: done"


class _Broken(_Reporter):
    def status_line(self) -> str:
        raise ZeroDivisionError("no data")


class _Silent:
    pass


async def test_status_display_joins_node_lines_and_prints_summary() -> None:
    out = io.StringIO()
    display = StatusDisplay([_Reporter("a"), _Silent(), _Reporter("b")], period_sec=1000.0, stream=out)
    async with display:
        line = display.status_line()
    assert line.endswith("] a: ok | b: ok")
    assert out.getvalue().splitlines()[-2:] == ["a: done", "b: done"]
    assert out.getvalue().splitlines()[0].startswith("ran ") and "with 3 nodes" in out.getvalue()


async def test_status_display_survives_a_broken_status_line() -> None:
    display = StatusDisplay([_Broken("x")], stream=io.StringIO())
    assert display.status_line().endswith("x: status_line() failed: ZeroDivisionError: no data")


async def test_status_display_without_reporting_nodes_counts_them() -> None:
    display = StatusDisplay([_Silent(), _Silent()], stream=io.StringIO())
    assert display.status_line().endswith("] 2 nodes running")
