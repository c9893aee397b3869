"""The README's examples work as written."""

import asyncio
import re
from pathlib import Path

from aiorobot import Node
from aiorobot.msgs.geometry_msgs import Twist
from aiorobot.testing import wait_for_message

README = (Path(__file__).resolve().parent.parent / "README.md").read_text()


class Talker(Node):
    def __init__(self, **kw):
        super().__init__("talker", **kw)
        self.pub = self.create_publisher(Twist, "/cmd_vel", 10)
        self.create_timer(0.02, self.tick)

    async def tick(self):
        self.pub.publish(Twist())


async def test_talker_publishes_cmd_vel(sim_runtime, sim_clock):
    probe = sim_runtime.add_node(Node("probe"))
    sim_runtime.add_node(Talker())
    waiting = asyncio.ensure_future(wait_for_message(probe, Twist, "/cmd_vel", timeout_sec=5))
    await sim_clock.advance(0.05)
    assert (await waiting).linear.x == 0.0


def test_readme_shows_this_test_verbatim():
    body = "\n".join(
        line for line in Path(__file__).read_text().splitlines()
        if line.startswith(("async def test_talker", "    probe", "    sim_runtime.add", "    waiting", "    await sim_clock", "    assert (await"))
    )
    readme = "\n".join(re.sub(r"\s+#.*$", "", line) for line in README.splitlines())
    assert body in readme


def test_ci_runs_the_readme_test_command():
    ci = (Path(__file__).resolve().parent.parent / ".ci" / "run").read_text()
    command = "pip install -e '.[test]' && python -m pytest"
    assert command in README and command in ci


def test_readme_pytest_example_runs_in_a_project_without_asyncio_mode_auto(tmp_path):
    """Copied as printed into a user's project (strict pytest-asyncio, no conftest): it passes."""
    import subprocess
    import sys

    block = README.split("## Testing your own nodes", 1)[1].split("```python\n", 1)[1].split("```", 1)[0]
    (tmp_path / "pytest.ini").write_text("[pytest]\nasyncio_mode = strict\n")
    (tmp_path / "talker.py").write_text(
        "from aiorobot import Node\nfrom aiorobot.msgs.geometry_msgs import Twist\n\n\n"
        "class Talker(Node):\n    def __init__(self, **kw):\n        super().__init__('talker', **kw)\n"
        "        self.pub = self.create_publisher(Twist, '/cmd_vel', 10)\n"
        "        self.create_timer(0.02, lambda: self.pub.publish(Twist()))\n"
    )
    (tmp_path / "test_talker.py").write_text(block)
    result = subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "test_talker.py"],
        cwd=tmp_path, capture_output=True, text=True, timeout=120,
    )
    assert result.returncode == 0, result.stdout + result.stderr
    assert "1 passed" in result.stdout
