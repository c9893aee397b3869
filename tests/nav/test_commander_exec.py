"""nav2_simple_commander's BasicNavigator under ``aiorobot exec``: a program making the calls of
Nav2's example_nav_to_pose.py (goToPose, isTaskComplete(task=), getFeedback(task=), a second goToPose
that preempts the first, getResult, getTaskError, lifecycleShutdown) reaches its goal in a real
subprocess beside the robot, map and navigation server of commander_world.py."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).parent
ROOT = HERE.parents[1]


def _exec(program: str) -> subprocess.CompletedProcess[str]:
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]),
               PYTHONUNBUFFERED="1")
    nodes = [arg for name in ("Robot", "Room", "Server") for arg in ("--node", f"tests.nav.commander_world:{name}")]
    return subprocess.run([sys.executable, "-m", "aiorobot.cli", "exec", *nodes, str(HERE / "fixtures" / program)],
                          capture_output=True, text=True, env=env, cwd=HERE / "fixtures", timeout=50)


def test_example_nav_to_pose_calls_reach_the_replacing_goal():
    run = _exec("commander_nav_to_pose.py")
    out = run.stdout.splitlines()
    assert run.returncode == 0, run.stdout + run.stderr
    assert out[0] == "task: RunningTask.NAVIGATE_TO_POSE"
    assert "replaced: RunningTask.NAVIGATE_TO_POSE" in out
    assert out[-1] == "Goal succeeded!", run.stdout
    assert "preempted by" in run.stderr  # the first goal ended aborted on the server
    assert any(line.startswith("Distance remaining: ") for line in out)
