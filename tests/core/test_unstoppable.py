"""A blocked callback never makes a robot unstoppable (issue 18, item 1).

Each case runs a real process that blocks a loop with ``time.sleep(60)`` (think: a blocking
serial read), sends it SIGINT, and checks that it ends well within the minute, with status 1
and a message naming what was blocked; and that a stall is reported once with its task and stack.
Bounds are generous (the machine is shared); nothing here measures time.
"""

from __future__ import annotations

import asyncio
import os
import signal
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

SCRIPT = textwrap.dedent(
    """
    import sys, time
    import aiorobot
    from aiorobot import Node, Runtime

    CASE, EXECUTOR = sys.argv[1], sys.argv[2]

    class Blocker(Node):
        def __init__(self):
            super().__init__("blocker")
            if CASE == "constructor":
                print("blocking", flush=True)
                time.sleep(60)
            self.create_timer(0.05, self.tick)

        def tick(self):
            if CASE == "callback":
                print("blocking", flush=True)
                time.sleep(60)

        async def on_start(self):
            if CASE == "on_shutdown":
                print("ready", flush=True)

        async def on_shutdown(self):
            if CASE == "on_shutdown":
                print("blocking", flush=True)
                time.sleep(60)

    async def main():
        async with Runtime(shutdown_timeout=2.0) as rt:
            rt.add_node(Blocker(), executor=EXECUTOR)
            await rt.spin()

    aiorobot.run(main())
    """
)


def _start(tmp_path: Path, *args: str) -> subprocess.Popen[str]:
    script = tmp_path / "blocker.py"
    script.write_text(SCRIPT)
    return subprocess.Popen([sys.executable, str(script), *args], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def _wait_line(proc: subprocess.Popen[str], word: str) -> None:
    assert proc.stdout is not None
    for line in proc.stdout:
        if word in line:
            return
    raise AssertionError(f"the process ended before printing {word!r}: {proc.stderr.read() if proc.stderr else ''}")


@pytest.mark.parametrize(
    ("case", "executor", "trigger"),
    [
        ("callback", "main", "blocking"),
        ("callback", "priority", "blocking"),
        ("on_shutdown", "main", "ready"),
        ("on_shutdown", "priority", "ready"),
        ("constructor", "main", "blocking"),
    ],
)
def test_sigint_ends_a_blocked_process_with_status_1_naming_the_blocker(tmp_path: Path, case: str, executor: str, trigger: str) -> None:
    proc = _start(tmp_path, case, executor)
    try:
        _wait_line(proc, trigger)
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=30)  # the sleep is 60 s: ending at all proves the point
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    assert proc.returncode == 1, err
    assert "blocked" in err, err
    assert ("/blocker" in err or "__init__" in err), err  # the task (node) or the frame (constructor) is named
    assert "Traceback" not in err, err


def test_a_second_sigint_exits_at_once(tmp_path: Path) -> None:
    proc = _start(tmp_path, "callback", "main")
    try:
        _wait_line(proc, "blocking")
        proc.send_signal(signal.SIGINT)
        assert proc.stderr is not None
        first = proc.stderr.readline()  # the first signal is acknowledged at once, loop blocked or not
        assert first == "aiorobot: SIGINT received: shutting down (within 2 s; again to force)\n"
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=30)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    assert proc.returncode == 1
    assert "SIGINT received again" in err and "the main loop in 'timer 0.05s of /blocker'" in err


async def test_a_stall_is_reported_once_with_its_task_and_stack_and_counted(caplog: pytest.LogCaptureFixture) -> None:
    import logging
    import time

    from aiorobot import Node, Runtime

    class Slow(Node):
        def __init__(self) -> None:
            super().__init__("slow")
            self.calls = 0
            self.create_timer(0.01, self.tick)

        def tick(self) -> None:
            self.calls += 1
            if self.calls == 3:
                time.sleep(0.4)  # blocks the priority loop far past its 50 ms threshold

    caplog.set_level(logging.WARNING, logger="aiorobot.runtime")
    async with Runtime(handle_signals=False) as rt:
        node = rt.add_node(Slow(), executor="priority")
        while node.calls < 10:
            await asyncio.sleep(0.05)
        stats = rt.stall_statistics()
    assert stats.counts.get("priority") == 1
    assert stats.stalls[0].task == "timer 0.01s of /slow"
    reports = [r.getMessage() for r in caplog.records if "loop stall" in r.getMessage()]
    assert len(reports) == 1
    assert "the priority loop in 'timer 0.01s of /slow'" in reports[0] and "time.sleep(0.4)" in reports[0]


BRIDGE_SCRIPT = textwrap.dedent(
    """
    import os, sys, time
    import aiorobot
    from aiorobot import Node, Runtime
    from aiorobot.control import MecanumController, SerialMotorBridge
    from aiorobot.msgs.geometry_msgs import Twist, Vector3

    JOINTS = ["front_left_wheel_joint", "front_right_wheel_joint", "rear_left_wheel_joint", "rear_right_wheel_joint"]

    class Driver(Node):
        def __init__(self):
            super().__init__("driver")
            self.pub = self.create_publisher(Twist, "/cmd_vel", 10)
            self.create_timer(0.02, lambda: self.pub.publish(Twist(linear=Vector3(x=0.2))))
            self.create_timer(0.02, self.maybe_block)

        def maybe_block(self):
            if os.path.exists(sys.argv[2]):
                print("blocking", flush=True)
                time.sleep(60)  # a blocking read on the main loop: the bridge beside it cannot run any more

    async def main():
        async with Runtime(shutdown_timeout=2.0) as rt:
            rt.add_node(SerialMotorBridge(parameter_overrides={"port": sys.argv[1], "reconnect_period_sec": 0.05, "joint_names": JOINTS}))
            rt.add_node(MecanumController(parameter_overrides={"wheel_radius": 0.05, "half_length": 0.15, "half_width": 0.15, "max_accel_x": 5.0}), executor="priority")
            rt.add_node(Driver())
            print("driving", flush=True)
            await rt.spin()

    aiorobot.run(main())
    """
)


async def test_the_firmware_gets_the_zero_command_even_when_the_bridges_loop_is_blocked(tmp_path: Path) -> None:
    from aiorobot.control import PtyFirmware, SimulatedFirmware, SetWheelVelocities

    path = str(tmp_path / "ttyMOTORS")
    firmware = PtyFirmware(SimulatedFirmware(host_timeout_sec=60.0), link_path=path)  # its own timeout out of the way
    await firmware.start()
    script = tmp_path / "bridge.py"
    script.write_text(BRIDGE_SCRIPT)
    trigger = tmp_path / "block-now"
    proc = await asyncio.create_subprocess_exec(sys.executable, str(script), path, str(trigger),
                                                stdout=asyncio.subprocess.PIPE, stderr=asyncio.subprocess.PIPE)
    try:
        async with asyncio.timeout(45):
            assert proc.stdout is not None
            while b"driving" not in await proc.stdout.readline():
                pass
            while not np.allclose(firmware.firmware.target_rad_s, 4.0):  # 0.2 m/s / 0.05 m on every wheel
                await asyncio.sleep(0.02)
            trigger.touch()
            while b"blocking" not in await proc.stdout.readline():
                pass
            assert np.allclose(firmware.firmware.target_rad_s, 4.0)  # nothing has stopped the wheels yet
            os.kill(proc.pid, signal.SIGINT)
            while not np.allclose(firmware.firmware.target_rad_s, 0.0):
                await asyncio.sleep(0.02)
            assert any(isinstance(m, SetWheelVelocities) and not any(m.velocities_rad_s) for m in firmware.firmware.received)
            _, err = await proc.communicate()
        assert proc.returncode == 1, err.decode()
    finally:
        if proc.returncode is None:
            proc.kill()
            await proc.wait()
        await firmware.close()
