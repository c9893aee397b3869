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
