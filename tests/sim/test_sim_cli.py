"""``aiorobot sim``: a config-free start, and one-line errors for bad arguments."""

from __future__ import annotations

import subprocess
import sys

from aiorobot.cli import main


def test_sim_runs_for_a_sim_duration_and_prints_a_summary() -> None:
    proc = subprocess.run(
        [sys.executable, "-m", "aiorobot.cli", "sim", "--world", "box", "--robot", "diff", "--duration", "2",
         "--rtf", "0", "--seed", "3"],
        capture_output=True, text=True, timeout=60,
    )
    assert proc.returncode == 0, proc.stderr
    assert "simulator: 2.00 s of sim time" in proc.stdout


def test_bad_world_and_bad_rtf_are_one_line_errors(capsys) -> None:
    assert main(["sim", "--world", "nowhere.yaml"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "nowhere.yaml: world file not found" in err
    try:
        main(["sim", "--rtf", "-2"])
    except SystemExit as exit_:
        assert exit_.code == 2
    err = capsys.readouterr().err
    assert "expected a real-time factor >= 0" in err and err.count("\n") == 1
