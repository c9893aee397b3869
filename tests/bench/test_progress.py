"""What ``aiorobot bench latency`` shows while it runs: bars on a terminal, a line per part elsewhere."""

from __future__ import annotations

import importlib.machinery
import io
import re
import sys
import types
from typing import Any

import pytest
from rich.console import Console

from aiorobot.bench import _runner
from aiorobot.bench._progress import BenchProgress
from aiorobot.bench._runner import run_benchmark


def _part_module(name: str, reports: bool) -> types.ModuleType:
    module = types.ModuleType(name)
    module.__spec__ = importlib.machinery.ModuleSpec(name, None)
    if reports:
        def run(quick: bool = False, progress: Any = None) -> dict[str, Any]:
            for k in range(1, 5):
                progress(k / 4)
            return {"figure": 1.0}
    else:
        def run(quick: bool = False) -> dict[str, Any]:
            return {"figure": 2.0}
    module.run = run  # type: ignore[attr-defined]
    return module


@pytest.fixture
def parts(monkeypatch: pytest.MonkeyPatch) -> None:
    for name, reports in (("telling", True), ("silent", False)):
        monkeypatch.setitem(sys.modules, f"_bench_{name}", _part_module(f"_bench_{name}", reports))
        monkeypatch.setitem(_runner.PARTS, name, f"_bench_{name}")


def test_a_part_that_takes_a_progress_callback_reports_its_fractions(parts: None) -> None:
    seen: list[tuple[str, float]] = []
    started: list[str] = []
    doc = run_benchmark(
        ["telling", "silent"], progress=started.append, fraction=lambda f: seen.append((started[-1], f))
    )
    assert started == ["telling", "silent"]
    assert seen == [("telling", 0.25), ("telling", 0.5), ("telling", 0.75), ("telling", 1.0)]
    assert doc["parts"]["silent"]["figure"] == 2.0


def test_on_a_terminal_each_part_gets_a_bar_then_a_line_with_its_time(parts: None) -> None:
    out = io.StringIO()
    console = Console(file=out, force_terminal=True, width=80)
    with BenchProgress(console, 2) as progress:
        run_benchmark(["telling", "silent"], progress=progress, fraction=progress.fraction)
    text = re.sub(r"\x1b\[[0-9;?]*[A-Za-z]", "", out.getvalue())  # the terminal's colours and cursor moves
    assert "parts 0/2" in text and "telling" in text
    assert "telling: 0.0 s" in text and "silent: 0.0 s" in text


def test_in_a_pipe_each_part_gets_one_line(parts: None) -> None:
    out = io.StringIO()
    console = Console(file=out, force_terminal=False, width=80)
    with BenchProgress(console, 2) as progress:
        run_benchmark(["telling", "silent"], progress=progress, fraction=progress.fraction)
    assert out.getvalue().splitlines() == ["running telling ...", "running silent ..."]
