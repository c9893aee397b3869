"""``aiorobot bench latency``: runs end to end (--quick), writes every figure, rejects bad arguments."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

from aiorobot.bench._runner import PARTS
from aiorobot.bench._seed import MODELS
from aiorobot.bench._workload import KINDS

pytestmark = pytest.mark.timeout(120)


def _aiorobot(*args: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "aiorobot.cli", *args], capture_output=True, text=True, cwd=cwd, timeout=110
    )


@pytest.fixture(scope="module")
def quick_run(tmp_path_factory: pytest.TempPathFactory) -> tuple[subprocess.CompletedProcess[str], dict[str, Any], Path]:
    tmp = tmp_path_factory.mktemp("bench")
    proc = _aiorobot("bench", "latency", "--quick", "--json", "out.json", "--plot", "out.png", cwd=tmp)
    doc = json.loads((tmp / "out.json").read_text()) if (tmp / "out.json").exists() else {}
    return proc, doc, tmp


def test_quick_run_succeeds_and_prints_every_table(quick_run) -> None:
    proc, _, _ = quick_run
    assert proc.returncode == 0, proc.stderr
    for title in ("Seed experiment", "Priority loop", "Publish -> callback latency", "CPU cost", "tf",
                  "demo: the whole simulated robot"):
        assert title in proc.stdout
    assert "rclpy SingleThreadedExecutor" in proc.stdout
    assert "rclpy MultiThreadedExecutor + groups" in proc.stdout
    assert "zenoh: two processes: see the zenoh transport table" in proc.stdout


def test_json_holds_every_part_model_and_kind(quick_run) -> None:
    _, doc, _ = quick_run
    assert set(doc["parts"]) == set(PARTS)
    assert doc["meta"]["quick"] is True and doc["meta"]["cpus"] >= 1
    seed = doc["parts"]["seed"]
    assert set(seed["models"]) == set(MODELS)
    for model in MODELS:
        for kind in KINDS:
            res = seed["models"][model][kind]
            assert "error" not in res, res
            assert res["stats"]["samples"] == seed["config"]["periods"] == len(res["periods_ms"])
            assert set(res["stats"]) >= {"mean_ms", "stdev_ms", "p50_ms", "p99_ms", "max_ms", "late_1ms", "late_5ms"}
            assert set(res["noise"]) == {"wall_sec", "steal_pct", "busy_pct", "load1", "others_pct"}
    assert seed["reference"]["rclpy SingleThreadedExecutor"]["max_ms"] == 172.1
    assert [(r["runtime"], r["main_loop"]) for r in doc["parts"]["timer"]["rows"]] == [
        ("Runtime()", "idle"),
        ("Runtime()", "busy (pure Python)"),
        ("Runtime(priority_realtime=True)", "idle"),
        ("Runtime(priority_realtime=True)", "busy (pure Python)"),
        ("bare thread, clock_nanosleep (floor)", "idle"),
        ("bare thread, clock_nanosleep (floor)", "idle"),
    ]
    for row in doc["parts"]["timer"]["rows"]:
        assert set(row["period_error"]) >= {"p50_us", "p99_us", "max_us"} and "thread_cpu_pct" in row
    paths = {(r["path"], r["payload"]) for r in doc["parts"]["latency"]["rows"]}
    for path in ("same loop", "main -> priority", "process pool round trip", "zenoh"):
        for payload in ("Twist", "Image 640x480x3"):
            assert (path, payload) in paths
    assert [r["case"] for r in doc["parts"]["cpu"]["rows"]][1] == "100 Hz publisher"
    assert doc["parts"]["cpu"]["reference"] == {"rclpy 100 Hz publisher": 16.0}
    assert "lookups_per_sec" in doc["parts"]["tf"]
    lockstep, realtime, fifo = doc["parts"]["demo"]["rows"]
    assert (lockstep["time_source"], lockstep["control_period_p99_ms"]) == ("sim", None)  # no wall periods in lock-step
    for row in (realtime, fifo):
        assert (row["time_source"], row["drive"]) == ("system", "serial") and row["control_periods"] > 0
        assert row["baseline_period_p99_ms"] is not None  # the bare-thread baseline of the same run
    assert (realtime["realtime"], "--realtime" in fifo["run"]) == (False, True)
    for row in (lockstep, realtime, fifo):
        assert row["waypoints_reached"] == row["waypoints_total"] > 0 and row["collisions"] == 0, row
        assert row["perception_fps"] > 0 and row["localisation_rmse_m"] < 0.15
    dds = doc["parts"]["dds"]  # the DDS transport and both bare cyclonedds-python pairs delivered
    assert all(dds[k]["n"] > 0 for k in ("twist", "bare_twist", "typed_twist", "image", "bare_image", "typed_image")), dds
    for name in PARTS:
        assert "noise" in doc["parts"][name]


def test_plot_is_a_png(quick_run) -> None:
    _, _, tmp = quick_run
    assert (tmp / "out.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_only_and_repeat_run_the_chosen_part_and_keep_each_repeat(tmp_path: Path) -> None:
    proc = _aiorobot("bench", "latency", "--quick", "--only", "cpu", "--repeat", "2", "--json", "o.json", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    doc = json.loads((tmp_path / "o.json").read_text())
    assert list(doc["parts"]) == ["cpu"]
    assert len(doc["repeats"]["cpu"]) == 2
    assert doc["meta"]["repeat"] == 2


def test_the_parts_own_nodes_keep_info_chatter_out_of_the_progress_display(tmp_path: Path) -> None:
    # the bag part's recorder and Foxglove bridge log INFO lines; they would tear the progress bars
    proc = _aiorobot("bench", "latency", "--quick", "--only", "bag", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert "[INFO]" not in proc.stderr and "recorded" in proc.stdout


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--repeat", "0"], "expected a whole number >= 1, found '0'"),
        (["--periods", "many"], "expected a whole number >= 1, found 'many'"),
        (["--only", "gpu"], f"expected one of {', '.join(PARTS)} (comma-separated), found 'gpu'"),
        (["--only", "timer", "--plot", "x.png"], "--plot draws the seed part's control periods"),
        (["--json", "no/such/folder/x.json"], "--json no/such/folder/x.json: the folder"),
        (["--frobnicate"], "unrecognized arguments: --frobnicate"),
    ],
)
def test_bad_arguments_exit_2_with_one_line(tmp_path: Path, args: list[str], message: str) -> None:
    proc = _aiorobot("bench", "latency", *args, cwd=tmp_path)
    assert proc.returncode == 2
    assert proc.stdout == ""
    lines = proc.stderr.splitlines()
    assert len(lines) == 1, proc.stderr
    assert message in lines[0]


def test_bench_without_a_benchmark_name_exits_2_with_one_line(tmp_path: Path) -> None:
    proc = _aiorobot("bench", cwd=tmp_path)
    assert proc.returncode == 2
    assert proc.stderr.splitlines() == ["aiorobot bench: error: expected a benchmark name: latency (see 'aiorobot bench --help')"]


def test_plot_without_matplotlib_exits_2_with_one_line(tmp_path: Path) -> None:
    code = (
        "import sys; sys.modules['matplotlib'] = None; from aiorobot.cli import main; "
        "sys.exit(main(['bench', 'latency', '--quick', '--plot', 'x.png']))"
    )
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path, timeout=60)
    assert proc.returncode == 2
    assert proc.stderr.splitlines() == [
        "aiorobot bench latency: error: --plot needs matplotlib, which is not installed: "
        "pip install 'aiorobot[plot]' (or matplotlib)"
    ]
