"""``aiorobot run``'s summary names the culprit of late priority periods."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

NODES = '''
import time
from aiorobot import Node


def _n():
    start = time.perf_counter()
    sum(range(100_000))
    return max(10_000, int(100_000 * 0.004 / max(time.perf_counter() - start, 1e-6)))


N = _n()  # about 4 ms of one GIL-holding C call


class Control(Node):
    def __init__(self, **kw):
        super().__init__("control", **kw)
        self.create_timer(0.01, lambda: None)


class Perception(Node):
    def __init__(self, **kw):
        super().__init__("perception", **kw)
        self.create_timer(0.007, self.perceive)

    def perceive(self):
        sum(range(N))  # a numpy operation that keeps the GIL, inline on the main loop
'''

GRAPH = '''
[[nodes]]
use = "gilnodes:Control"
executor = "priority"
[[nodes]]
use = "gilnodes:Perception"
'''


def test_run_summary_names_perception_as_the_top_cause_of_late_periods(tmp_path: Path) -> None:
    (tmp_path / "gilnodes.py").write_text(NODES)
    (tmp_path / "graph.toml").write_text(GRAPH)
    proc = subprocess.run(
        [sys.executable, "-m", "aiorobot.cli", "run", "graph.toml", "--duration", "2"],
        capture_output=True, text=True, timeout=50, cwd=tmp_path,
    )
    assert proc.returncode == 0, proc.stderr
    lines = proc.stderr.splitlines()
    (head,) = [i for i, line in enumerate(lines) if line.startswith("late priority periods: ")]
    assert lines[head].endswith(" started more than 1 ms after their deadline; top causes:")
    causes = [line for line in lines[head + 1:] if line.startswith("  ")]
    # the first function named (on a loaded machine "(no Python thread)", the OS, may come before it)
    named = [line for line in causes if not line.startswith("  (")]
    assert named[0].startswith("  Perception.perceive (timer 0.007s of /perception) at gilnodes.py:"), proc.stderr
