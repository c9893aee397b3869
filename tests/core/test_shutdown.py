"""Shutdown: on_shutdown hooks, last messages delivered, pools stopped, nothing left pending."""

import asyncio
import os
import signal
import subprocess
import sys
import textwrap

import pytest

from aiorobot import Node, Runtime
from aiorobot.msgs.std_msgs import Int32


class Controller(Node):
    def __init__(self):
        super().__init__("controller")
        self.pub = self.create_publisher(Int32, "/wheels", 10)

    async def on_shutdown(self):
        self.pub.publish(Int32(data=0))  # the last command: stop


class Hardware(Node):
    def __init__(self):
        super().__init__("hardware")
        self.commands = []
        self.create_subscription(Int32, "/wheels", self.on_cmd, 10)

    async def on_cmd(self, msg):
        await asyncio.sleep(0)
        self.commands.append(msg.data)


@pytest.mark.parametrize(("ctrl_exec", "hw_exec"), [("priority", "main"), ("main", "priority"), ("main", "main")])
async def test_on_shutdown_message_reaches_its_subscriber_before_exit(ctrl_exec, hw_exec):
    hw = Hardware()
    async with Runtime(handle_signals=False) as rt:
        rt.add_node(Controller(), executor=ctrl_exec)
        rt.add_node(hw, executor=hw_exec)
    assert hw.commands == [0]


async def test_no_task_is_left_pending_after_close():
    before = asyncio.all_tasks()
    async with Runtime(handle_signals=False) as rt:
        node = rt.add_node(Hardware())
        rt.add_node(Controller(), executor="priority")
        node.create_timer(0.01, lambda: None)
        await asyncio.sleep(0)
    assert asyncio.all_tasks() == before
    assert rt.priority_loop is None


async def test_shutdown_hook_that_raises_is_logged_and_others_still_run(caplog):
    class Broken(Node):
        async def on_shutdown(self):
            raise RuntimeError("hook failed")

    hw = Hardware()
    async with Runtime(handle_signals=False) as rt:
        rt.add_node(Broken("broken"))
        rt.add_node(Controller())
        rt.add_node(hw)
    assert hw.commands == [0]
    assert "on_shutdown of /broken raised" in caplog.text


async def test_spin_returns_on_shutdown_from_another_thread():
    async with Runtime(handle_signals=False) as rt:
        node = rt.add_node(Node("n"))
        await node.run_in_thread(rt.shutdown)
        await asyncio.wait_for(rt.spin(), 30)
        assert rt.is_shutdown


async def test_spin_needs_an_entered_runtime():
    with pytest.raises(RuntimeError, match="async with Runtime"):
        await Runtime().spin(0)


SCRIPT = textwrap.dedent(
    """
    import asyncio, sys
    import aiorobot
    from aiorobot import Node, Runtime
    from aiorobot.msgs.std_msgs import Int32

    async def square(x):
        return x * x

    class N(Node):
        def __init__(self):
            super().__init__("n")
            self.create_timer(0.01, lambda: None)
        async def on_start(self):
            print("ready", await self.offload(pow, 3, 2), flush=True)
        async def on_shutdown(self):
            print("on_shutdown", flush=True)

    async def main():
        async with Runtime() as rt:
            rt.add_node(N(), executor="priority")
            await rt.spin()
        print("clean exit", flush=True)

    if __name__ == "__main__":
        aiorobot.run(main())
    """
)


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_signal_shuts_down_cleanly_with_no_warnings(tmp_path, sig):
    script = tmp_path / "app.py"
    script.write_text(SCRIPT)
    env = {**os.environ, "PYTHONWARNINGS": "error"}
    proc = subprocess.Popen(
        [sys.executable, str(script)], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env
    )
    try:
        assert proc.stdout.readline().strip() == "ready 9"
        proc.send_signal(sig)
        out, err = proc.communicate(timeout=60)
    finally:
        proc.kill()
    assert proc.returncode == 0, err
    assert out.split() == ["on_shutdown", "clean", "exit"]
    assert "Traceback" not in err and "Task was destroyed" not in err and "Warning" not in err
