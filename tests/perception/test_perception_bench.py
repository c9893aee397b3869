"""The bench part ``perception`` runs (quick) and reports every row; figures are not asserted (timing)."""

from __future__ import annotations

import math

from aiorobot.bench._runner import PARTS


def test_perception_part_runs_quick_and_draws_its_table():
    from rich.console import Console

    from aiorobot.bench import _perception

    assert PARTS["perception"] == "aiorobot.bench._perception"
    part = _perception.run(quick=True)
    assert part["aruco"]["markers_found"] == 4
    for row in ("inline_fps", "workers_1_fps", "workers_2_fps"):
        assert part["aruco"][row] > 0
    for path in ("ring", "offload"):
        assert part["transport"][path]["handoff_p50_ms"] > 0
        assert part["transport"][path]["to_worker_p50_ms"] > 0
    assert part["seed"]["periods"] == 25
    assert all(math.isfinite(part["seed"][k]) for k in ("control_p99_ms", "control_max_ms", "added_latency_p50_ms"))
    console = Console(width=120, record=True)
    console.print(_perception.table(part))
    text = console.export_text()
    assert "frame ring: main-process cost per 640x480x3 frame" in text and "pipeline 2 workers fps" in text
