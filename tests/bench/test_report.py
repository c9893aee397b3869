"""The report prints every part's figures, the reference rows and failures, from a document alone."""

from __future__ import annotations

from typing import Any

from rich.console import Console

from aiorobot.bench._cli import _failures
from aiorobot.bench._report import print_report
from aiorobot.bench._seed import REFERENCE
from aiorobot.bench._stats import period_stats

NOISE = {"wall_sec": 1.0, "steal_pct": 12.5, "busy_pct": 60.0, "load1": 1.5, "others_pct": 40.0}


def _doc() -> dict[str, Any]:
    stats = period_stats([20.0, 20.5, 27.0], 20.0).as_dict()
    return {
        "meta": {"date_utc": "2026-01-01 00:00 UTC", "cpus": 2, "python": "3.11", "platform": "Linux", "repeat": 1, "noise": NOISE},
        "parts": {
            "seed": {
                "config": {"control_period_sec": 0.02, "perception_period_sec": 0.1, "work_sec": 0.15, "periods": 3, "warmup": 1},
                "models": {
                    "single": {"cpu": {"stats": stats, "periods_ms": [20.0, 20.5, 27.0], "noise": NOISE}},
                    "aiorobot": {"cpu": {"error": "RuntimeError: no priority loop"}},
                },
                "reference": REFERENCE,
            },
            "cpu": {"rows": [{"case": "100 Hz publisher", "core_pct": 0.75, "noise": NOISE}], "reference": {"rclpy 100 Hz publisher": 16.0}},
            "tf": {"error": "not available: aiorobot.bench.tf is not installed"},
        },
    }


def _render(doc: dict[str, Any]) -> str:
    console = Console(record=True, width=250)
    print_report(doc, console)
    return console.export_text()


def test_report_shows_figures_noise_and_reference_rows() -> None:
    text = _render(_doc())
    assert "27.0" in text  # the max period
    assert "12.5" in text  # steal beside the row
    assert "rclpy SingleThreadedExecutor" in text and "172.1" in text
    assert "rclpy 100 Hz publisher" in text and "0.75" in text


def test_report_names_a_model_or_part_that_could_not_run() -> None:
    text = _render(_doc())
    assert "RuntimeError: no priority loop" in text
    assert "tf: not available: aiorobot.bench.tf is not installed" in text


def test_failures_lists_failed_parts_and_models() -> None:
    assert _failures(_doc()) == ["seed/aiorobot/cpu", "tf"]


def test_a_part_outside_the_builtin_ones_is_drawn_by_its_own_module(monkeypatch: Any) -> None:
    import sys
    import types

    from aiorobot.bench import _runner
    from aiorobot.bench._report import figure_table

    module = types.ModuleType("_bench_part_for_test")
    module.table = lambda part: figure_table("extra part", ("case", "value"), [(k, v) for k, v in part.items()])  # type: ignore[attr-defined]
    monkeypatch.setitem(sys.modules, "_bench_part_for_test", module)
    monkeypatch.setitem(_runner.PARTS, "extra", "_bench_part_for_test")
    console = Console(width=120, record=True)
    print_report({"meta": {}, "parts": {"extra": {"scan ms": 0.25}}}, console)
    text = console.export_text()
    assert "extra part" in text and "scan ms" in text and "0.25" in text


def _wide_doc() -> dict[str, Any]:
    doc = _doc()
    stats = period_stats([20.0, 20.5, 27.0], 20.0).as_dict()
    doc["parts"]["seed"]["models"]["threads"] = {"sleep": {"stats": stats, "noise": NOISE}, "cpu": {"stats": stats, "noise": NOISE}}
    return doc


def test_an_80_column_terminal_gets_stacked_tables_with_every_figure_whole() -> None:
    console = Console(record=True, width=80)
    print_report(_wide_doc(), console)
    text = console.export_text()
    assert "…" not in text
    assert max(len(line) for line in text.splitlines()) <= 80
    # every figure of the seed table is there, whole: max 27.0, steal 12.5, load 1.50, rclpy's published 172.1
    for figure in ("27.0", "12.5", "1.50", "172.1", "RuntimeError: no priority loop"):
        assert figure in text.replace("\n", " ") or figure in text, figure
    # the stacked tables repeat the row labels (model and work) so each row stays readable
    seed_tables = text.split("Seed experiment")[1].split("CPU cost")[0]
    assert seed_tables.count("┃ model") >= 2 and seed_tables.count("┃ work") >= 2


def test_a_wide_terminal_keeps_one_table_per_part() -> None:
    text = _render(_wide_doc())
    assert text.split("Seed experiment")[1].split("CPU cost")[0].count("┃ model") == 1


def test_the_headline_comes_first_control_p99_and_max_per_model() -> None:
    text = _render(_wide_doc())
    first = text.lstrip().splitlines()[0]
    assert first.startswith("Headline: 20 ms control period")
    headline = text.split("aiorobot bench latency")[0]
    row = next(line for line in headline.splitlines() if "threads" in line)
    assert [c.strip() for c in row.split("│")[2:6]] == ["26.9", "27.0", "26.9", "27.0"]
    assert "failed" in next(line for line in headline.splitlines() if "aiorobot" in line)


def test_no_headline_without_the_seed_part() -> None:
    doc = _doc()
    del doc["parts"]["seed"]
    assert "Headline" not in _render(doc)
