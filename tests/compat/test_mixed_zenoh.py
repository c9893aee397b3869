"""Mixed graphs over zenoh: an rclpy program under ``aiorobot exec --transport zenoh`` and native
aiorobot nodes in another process (and in its own), on a real zenoh router on loopback."""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
import textwrap
from collections.abc import Iterator

import pytest

from ._run import ROOT, Program

NATIVE = textwrap.dedent("""
    import asyncio, signal, sys
    import aiorobot
    from aiorobot import Runtime
    from aiorobot.transport import ZenohTransport
    from tests.compat import native_nodes

    async def main():
        async with Runtime(transport=ZenohTransport(connect=[sys.argv[1]]), handle_signals=False) as rt:
            for name in sys.argv[2:]:
                rt.add_node(getattr(native_nodes, name)())
            stop = asyncio.Event()
            asyncio.get_running_loop().add_signal_handler(signal.SIGINT, stop.set)
            print("native ready", flush=True)
            await stop.wait()

    aiorobot.run(main())
""")


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


@pytest.fixture
def router() -> Iterator[str]:
    import zenoh

    endpoint = f"tcp/127.0.0.1:{_free_port()}"
    cfg = zenoh.Config()
    cfg.insert_json5("mode", '"router"')
    cfg.insert_json5("listen/endpoints", f'["{endpoint}"]')
    cfg.insert_json5("scouting/multicast/enabled", "false")
    session = zenoh.open(cfg)
    try:
        yield endpoint
    finally:
        session.close()


class Native(Program):
    """A native aiorobot process (no rclpy) with ``nodes`` from native_nodes, on zenoh."""

    def __init__(self, endpoint: str, *nodes: str) -> None:  # noqa: D107 - reuses Program's reader
        import threading

        env = dict(os.environ)
        env.pop("ZENOH_CONFIG_OVERRIDE", None)
        env["PYTHONPATH"] = os.pathsep.join([str(ROOT), env.get("PYTHONPATH", "")])
        self.proc = subprocess.Popen(
            [sys.executable, "-c", NATIVE, endpoint, *nodes], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
            text=True, env=env, cwd=ROOT,
        )
        self.lines = []
        self._eof = False
        self._changed = threading.Condition()
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()


def _rclpy(endpoint: str, script: str, nodes: tuple[str, ...] = ()) -> Program:
    return Program(
        script, nodes=nodes, exec_args=("--transport", "zenoh"),
        extra_env={"ZENOH_CONFIG_OVERRIDE": f'connect/endpoints=["{endpoint}"]'},
    )


def test_an_rclpy_talker_reaches_a_native_listener_in_its_process_and_in_another(router):
    native = Native(router, "Listener")
    try:
        native.wait_for("native ready")
        talker = _rclpy(router, "demo_nodes_py/topics/talker.py", nodes=("Listener",))
        talker.wait_for("native heard: Hello World: 2")  # the native node in the rclpy program's process
        native.wait_for("native heard: Hello World: 2")  # the one in the other process, over zenoh
        assert talker.stop() == 0, talker.output
    finally:
        native.stop()
    assert "Traceback" not in native.output + talker.output


def test_an_rclpy_listener_and_client_use_native_nodes_in_another_process(router):
    native = Native(router, "Talker", "AddTwoIntsServer")
    try:
        native.wait_for("native ready")
        listener = _rclpy(router, "demo_nodes_py/topics/listener.py")
        listener.wait_for("I heard: [native", count=3)
        assert listener.stop() == 0, listener.output
        client = _rclpy(router, "examples_rclpy_minimal_client/client.py")
        client.wait_for("Result of add_two_ints: for 41 + 1 = 42")
        assert client.finish() == 0, client.output
        native.wait_for("native server: 41 + 1")
    finally:
        native.stop()
    assert native.proc.returncode in (0, -signal.SIGINT), native.output


def test_a_program_that_never_spins_still_publishes_to_other_processes(router):
    """publisher_old_school.py publishes in a plain loop: rmw sends without spinning, so does zenoh here."""
    native = Native(router, "Listener")
    try:
        native.wait_for("native ready")
        talker = _rclpy(router, "examples_rclpy_minimal_publisher/publisher_old_school.py")
        native.wait_for("native heard: Hello World: 2")
        assert talker.stop() == 0, talker.output
    finally:
        native.stop()
    assert "Traceback" not in talker.output
