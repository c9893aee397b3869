"""Steal and load figures from the text of /proc files."""

from __future__ import annotations

import pytest

from aiorobot.bench._noise import CpuTimes, NoiseMeter, noise_between, parse_loadavg, parse_proc_stat

PROC_STAT = """cpu  100 5 50 800 10 2 3 30 0 0
cpu0 50 2 25 400 5 1 1 15 0 0
intr 12345
"""


def test_parse_proc_stat_reads_the_aggregate_cpu_line() -> None:
    t = parse_proc_stat(PROC_STAT)
    assert t == CpuTimes(user=100, nice=5, system=50, idle=800, iowait=10, irq=2, softirq=3, steal=30)
    assert t.total == 1000
    assert t.busy == 160


def test_parse_proc_stat_without_steal_column_counts_zero_steal() -> None:
    assert parse_proc_stat("cpu 1 2 3 4\n").steal == 0


def test_parse_proc_stat_names_the_missing_line() -> None:
    with pytest.raises(ValueError, match=r"^expected a line starting with 'cpu '"):
        parse_proc_stat("intr 1\n")


def test_parse_loadavg_reads_the_one_minute_load() -> None:
    assert parse_loadavg("1.25 0.80 0.40 2/150 4242\n") == 1.25
    with pytest.raises(ValueError, match="expected /proc/loadavg to start with a number"):
        parse_loadavg("")


def test_noise_between_gives_steal_and_busy_shares_of_the_interval() -> None:
    before = CpuTimes(100, 0, 50, 800, 0, 0, 0, 50)
    after = CpuTimes(160, 0, 70, 850, 0, 0, 0, 70)  # +150 ticks: 60 user, 20 system, 50 idle, 20 steal
    sample = noise_between(before, after, wall_sec=1.5, load1=0.7)
    assert sample.steal_pct == pytest.approx(100 * 20 / 150)
    assert sample.busy_pct == pytest.approx(100 * 80 / 150)
    assert (sample.wall_sec, sample.load1) == (1.5, 0.7)
    assert sample.others_pct is None


def test_noise_between_subtracts_our_own_cpu_from_the_busy_share() -> None:
    before = CpuTimes(100, 0, 50, 800, 0, 0, 0, 50)
    after = CpuTimes(160, 0, 70, 850, 0, 0, 0, 70)  # 80 busy ticks of 150
    sample = noise_between(before, after, wall_sec=1.5, load1=0.7, own_ticks=30)
    assert sample.others_pct == pytest.approx(100 * 50 / 150)
    assert noise_between(before, after, 1.5, 0.7, own_ticks=500).others_pct == 0.0


def test_noise_between_an_empty_interval_is_quiet() -> None:
    t = CpuTimes(1, 1, 1, 1, 1, 1, 1, 1)
    assert noise_between(t, t, 0.0, None).steal_pct == 0.0


def test_noise_meter_reports_after_its_block() -> None:
    with NoiseMeter() as meter:
        assert meter.result is None
    assert meter.result is not None
    assert meter.result.wall_sec >= 0.0
    assert set(meter.result.as_dict()) == {"wall_sec", "steal_pct", "busy_pct", "load1", "others_pct"}
