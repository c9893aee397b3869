"""``aiorobot demo`` on a map of the user's (a Nav2 map) and bounded by ``--duration`` (issues 25 item 3, 26 item 9).

The map is written here, shaped like nav2_bringup's ``turtlebot3_world`` (a pillar on the origin, a
negative origin, no ``start`` key) and named ``warehouse.yaml`` like Nav2's own warehouse map: a path
is a path, so it does not get the built-in warehouse's mission.
"""

from __future__ import annotations

import signal
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from aiorobot.cli import main
from aiorobot.demo import DemoSetupError, DemoSummary, mission_for, run_demo

pytestmark = pytest.mark.timeout(120)


def _nav2_like_map(directory: Path, name: str = "warehouse") -> Path:
    image = np.full((120, 120), 205, dtype=np.uint8)  # unknown
    image[10:-10, 10:-10] = 0  # walls
    image[12:-12, 12:-12] = 254  # the mapped free arena, x and y from -2.4 to 2.4 m
    image[56:64, 56:64] = 0  # a pillar on the origin...
    image[58:62, 58:62] = 205  # ...whose inside was never seen
    (directory / f"{name}.pgm").write_bytes(b"P5\n120 120\n255\n" + image.tobytes())
    path = directory / f"{name}.yaml"
    path.write_text(f"image: {name}.pgm\nmode: trinary\nresolution: 0.05\norigin: [-3.0, -3.0, 0.0]\nnegate: 0\n"
                    "occupied_thresh: 0.65\nfree_thresh: 0.196\n")
    return path


def test_only_a_bare_built_in_name_has_a_mission(tmp_path: Path) -> None:
    path = _nav2_like_map(tmp_path)
    assert mission_for("warehouse") is not None and len(mission_for("warehouse") or []) == 7
    assert mission_for(str(path)) is None and mission_for("warehouse.yaml") is None


async def test_run_demo_refuses_a_map_without_waypoints_before_starting(tmp_path: Path) -> None:
    with pytest.raises(DemoSetupError, match=r"warehouse\.yaml' has no shipped mission .* give the waypoints"):
        await run_demo(str(_nav2_like_map(tmp_path)))


def test_cli_errors_for_a_map_are_one_line_without_a_traceback(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = _nav2_like_map(tmp_path)
    cases = [
        (["--world", str(path)], "warehouse.yaml' has no shipped mission"),
        (["--world", str(path), "--waypoints", "-0.55,-0.55", "--start", "0.1,0"], "start (0.1, 0) is inside an obstacle"),
        (["--world", str(path), "--waypoints", "0,0"], "waypoint 1 (0, 0) is outside the map or inside an obstacle"),
        (["--world", str(tmp_path / "missing.yaml"), "--waypoints", "1,1"], "missing.yaml: world file not found"),
    ]
    (tmp_path / "void.pgm").write_bytes(b"P5\n20 20\n255\n" + bytes([205]) * 400)
    (tmp_path / "void.yaml").write_text("image: void.pgm\nresolution: 0.05\norigin: [-0.5, -0.5, 0]\n")
    cases.append((["--world", str(tmp_path / "void.yaml"), "--waypoints", "0.1,0.1"], "no known-free spot"))
    for args, message in cases:
        assert main(["demo", *args]) == 2, args
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and err.startswith("aiorobot demo: error: ") and message in err, (args, err)


def test_a_nav2_map_runs_from_the_nearest_free_cell_with_one_warning(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = _nav2_like_map(tmp_path)
    status = main(["demo", "--world", str(path), "--waypoints", "-0.55,-0.55", "--rtf", "0", "--no-perception",
                   "--json", str(tmp_path / "summary.json")])
    out = capsys.readouterr()
    assert status == 0, out.err
    assert "aiorobot demo: warning: " in out.err and "the origin (0, 0) is inside an obstacle" in out.err
    assert "Traceback" not in out.err
    import json

    figures = json.loads((tmp_path / "summary.json").read_text())
    assert figures["world"] == str(path) and figures["waypoints_reached"] == 1 and figures["collisions"] == 0
    assert figures["start"] != [0.0, 0.0, 0.0]


def test_a_run_stopped_by_its_duration_exits_0_and_says_so(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    # the first waypoint is 0.5 m away, the second 4.3 m beyond it: 5 sim seconds reach one, not both
    status = main(["demo", "--world", "box", "--waypoints", "0.5,0;-2.5,2.5", "--duration", "5", "--rtf", "0",
                   "--no-perception", "--json", str(tmp_path / "summary.json")])
    out = capsys.readouterr()
    assert status == 0, out.err
    assert "aiorobot demo — box, direct drive, amcl, rpp: stopped after --duration: 1 / 2 waypoints" in out.out
    import json

    figures = json.loads((tmp_path / "summary.json").read_text())
    assert figures["stopped_by_duration"] and figures["status"] == "STOPPED" and figures["duration_sec"] == 5.0
    assert figures["collisions"] == 0 and figures["failures"] == [] and figures["sim_sec"] >= 5.0


def test_what_passes_the_exit_status() -> None:
    stopped = DemoSummary(world="box", waypoints_total=3, stopped_by_duration=True)
    assert stopped.passed and not stopped.succeeded
    assert not DemoSummary(world="box", waypoints_total=3, stopped_by_duration=True, collisions=1).passed
    assert not DemoSummary(world="box", waypoints_total=3, stopped_by_duration=True, failures=["/amcl: x raised"]).passed
    assert not DemoSummary(world="box", waypoints_total=3, waypoints_reached=2).passed  # timed out: a failure
    assert DemoSummary(world="box", waypoints_total=3, waypoints_reached=3).passed


def test_ctrl_c_still_exits_130() -> None:
    proc = subprocess.Popen([sys.executable, "-m", "aiorobot.cli", "demo", "--world", "box", "--rtf", "0",
                             "--no-perception", "--duration", "500"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        assert proc.stderr is not None
        for line in proc.stderr:  # not a terminal: one progress line at a time, once the mission runs
            if line.startswith("sim "):
                break
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode == 130, err
    assert "aiorobot demo: interrupted" in err
