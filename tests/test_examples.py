"""The ported seed examples run as files and do what they say."""

import subprocess
import sys
from pathlib import Path

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"


def _run(*args):
    proc = subprocess.run([sys.executable, *map(str, args)], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    return proc.stdout


def test_add_two_ints_example():
    assert _run(EXAMPLES / "add_two_ints.py", 40, 2).strip() == "Result of add_two_ints: for 40 + 2 = 42"


def test_fibonacci_example_runs_to_success():
    out = _run(EXAMPLES / "fibonacci_action.py", 5).splitlines()
    assert out[0] == "feedback: [0, 1, 1]"
    assert out[-1] == "result (SUCCEEDED): [0, 1, 1, 2, 3, 5]"


def test_fibonacci_example_cancels():
    out = _run(EXAMPLES / "fibonacci_action.py", 40, "--cancel").splitlines()
    assert "cancel accepted: True" in out
    assert out[-1].startswith("result (CANCELED): [0, 1, 1, 2, 3")


def test_two_dof_arm_example_prints_reachable_tool_positions():
    import math
    import re

    out = _run(EXAMPLES / "two_dof_arm.py")
    points = [
        tuple(map(float, m.groups()))
        for m in re.finditer(r"tool0 in base_link: x=([-+.\d]+) y=([-+.\d]+) z=([-+.\d]+) m", out)
    ]
    assert len(points) >= 3
    shoulder = (0.1, 0.0, 0.30)  # mount (0.1, 0, 0.25) + shoulder (0, 0, 0.05) in the URDF
    for p in points:
        reach = math.dist(p, shoulder)
        assert 0.05 - 1e-3 <= reach <= 0.55 + 1e-3  # |upper arm 0.30 - forearm 0.25| .. their sum
    assert len(set(points)) > 1  # the joints sweep
