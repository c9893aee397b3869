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
