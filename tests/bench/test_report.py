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
