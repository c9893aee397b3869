"""``aiorobot run`` of a graph spread over child processes: real processes on loopback zenoh.

A pinger in process ``a`` talks to an echo node in process ``b``; the supervisor restarts
``b`` after a SIGKILL, stops everything on SIGTERM/SIGINT and reports failures in its
exit status.
"""

from __future__ import annotations

import asyncio
import os
import signal
import sys
import textwrap
from pathlib import Path

import pytest

from aiorobot.launch import ConfigError, parse_config

NODES = '''
import os
from aiorobot import Node
from aiorobot.msgs.std_msgs import String


class Pinger(Node):
    def __init__(self, **kw):
        super().__init__("pinger", **kw)
        self.pub = self.create_publisher(String, "ping", 10)
        self.create_subscription(String, "pong", lambda m: print("pong", m.data, flush=True), 10)
        self.n = 0
        self.create_timer(0.02, self.tick)

    def tick(self):
        self.n += 1
        self.pub.publish(String(data=str(self.n)))


class Echo(Node):
    def __init__(self, **kw):
        super().__init__("echo", **kw)
        self.pub = self.create_publisher(String, "pong", 10)
        self.create_subscription(String, "ping", self.on_ping, 10)

    def on_ping(self, msg):
        self.pub.publish(String(data=f"{os.getpid()}:{msg.data}"))


class Quitter(Node):
    """Fails at once: its process ends with status 1."""

    def __init__(self, **kw):
        super().__init__("quitter", **kw)

    async def on_start(self):
        raise RuntimeError("no camera")
'''


def _write(tmp_path: Path, body: str) -> Path:
    (tmp_path / "mp_nodes.py").write_text(NODES)
    config = tmp_path / "graph.toml"
    # a domain of its own: other zenoh graphs on this machine must not answer our pings
    config.write_text(f"[runtime]\ndomain_id = {100 + os.getpid() % 100}\nshutdown_timeout = 5\n" + textwrap.dedent(body))
    return config


class Run:
    """``aiorobot run CONFIG`` as a child of the test, its output read line by line."""

    def __init__(self, proc: asyncio.subprocess.Process) -> None:
        self.proc = proc
        self.out: list[str] = []
        self.err: list[str] = []
        self._err_task = asyncio.create_task(self._drain_err())

    @classmethod
    async def start(cls, config: Path, *args: str) -> Run:
        env = dict(os.environ, PYTHONUNBUFFERED="1")
        env.pop("ZENOH_CONFIG_OVERRIDE", None)
        proc = await asyncio.create_subprocess_exec(
            sys.executable, "-m", "aiorobot.cli", "run", str(config), "--status-period", "30", *args,
            stdout=asyncio.subprocess.PIPE, stderr=asyncio.subprocess.PIPE, env=env,
        )
        return cls(proc)

    async def _drain_err(self) -> None:
        assert self.proc.stderr is not None
        while raw := await self.proc.stderr.readline():
            self.err.append(raw.decode().rstrip("\n"))

    async def line(self, prefix: str, timeout_sec: float = 30.0) -> str:
        assert self.proc.stdout is not None
        async with asyncio.timeout(timeout_sec):
            while True:
                raw = await self.proc.stdout.readline()
                if not raw:
                    await self._err_task
                    raise AssertionError(f"aiorobot run ended before printing {prefix!r}:\n" + "\n".join(self.err[-30:]))
                text = raw.decode().rstrip("\n")
                self.out.append(text)
                if text.startswith(prefix):
                    return text

    async def finish(self, timeout_sec: float = 30.0) -> int:
        assert self.proc.stdout is not None
        async with asyncio.timeout(timeout_sec):
            self.out += (await self.proc.stdout.read()).decode().splitlines()
            await self._err_task
            return await self.proc.wait()

    def kill(self) -> None:
        if self.proc.returncode is None:
            self.proc.kill()


def _gone(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return True
    return False


TWO_CHILDREN = """
[[nodes]]
use = "mp_nodes:Pinger"
process = "a"

[[nodes]]
use = "mp_nodes:Echo"
process = "b"

[processes.b]
restart = "on-failure"
restart_delay = 0.1
"""


async def test_a_child_killed_with_sigkill_is_restarted_and_sigterm_stops_all_with_status_1(tmp_path: Path) -> None:
    run = await Run.start(_write(tmp_path, TWO_CHILDREN))
    try:
        first = await run.line("[a] pong ")  # process a's node got an answer from process b's
        echo_pid = int(first.split()[2].split(":")[0])
        os.kill(echo_pid, signal.SIGKILL)
        while True:  # messages flow again, from a new process b
            line = await run.line("[a] pong ")
            new_pid = int(line.split()[2].split(":")[0])
            if new_pid != echo_pid:
                break
        run.proc.send_signal(signal.SIGTERM)
        status = await run.finish()
    finally:
        run.kill()
    assert status == 1, "\n".join(run.err)  # a child failed during the run, even though it was restarted
    assert "  process b: killed by SIGKILL" in run.err
    assert any("process b killed by SIGKILL; restarting in 0.1 s (restart 1 of at most 5)" in e for e in run.err)
    assert any(e.startswith("[a] ") and "SIGTERM received" in e for e in run.err)  # each child's own shutdown
    assert _gone(new_pid)


async def test_sigint_ends_every_child_cleanly_with_status_0(tmp_path: Path) -> None:
    config = _write(tmp_path, TWO_CHILDREN.replace('process = "a"', "") + "\n")  # the pinger in aiorobot run itself
    run = await Run.start(config)
    try:
        line = await run.line("pong ")  # the main process's node hears the child's
        pid = int(line.split()[1].split(":")[0])
        run.proc.send_signal(signal.SIGINT)
        status = await run.finish()
    finally:
        run.kill()
    assert status == 0, "\n".join(run.err)
    assert any(e.startswith("[b] ") and "SIGTERM received" in e for e in run.err)
    assert not any("failures" in e for e in run.err)
    assert _gone(pid)


async def test_a_required_process_that_fails_and_is_not_restarted_ends_the_graph_with_status_1(tmp_path: Path) -> None:
    config = _write(tmp_path, """
        [[nodes]]
        use = "mp_nodes:Echo"

        [[nodes]]
        use = "mp_nodes:Quitter"
        process = "camera"

        [processes.camera]
        restart = "no"
        required = true
        """)
    run = await Run.start(config)
    try:
        status = await run.finish()
    finally:
        run.kill()
    assert status == 1
    assert any("process camera exited with status 1; not restarted; required: shutting the graph down" in e for e in run.err)
    assert any(e.startswith("[camera] ") and "no camera" in e for e in run.err)
    assert "  process camera: exited with status 1" in run.err


async def test_a_bad_node_in_a_child_process_starts_no_process(tmp_path: Path) -> None:
    config = _write(tmp_path, """
        [[nodes]]
        use = "mp_nodes:Pinger"

        [[nodes]]
        use = "mp_nodes:Echo"
        process = "b"
        parameters = { gain = 2.0 }
        """)
    run = await Run.start(config)
    try:
        status = await run.finish()
    finally:
        run.kill()
    assert status == 2
    assert len(run.err) == 1 and run.err[0].startswith(f"{config}: nodes[1].parameters.gain: expected a parameter declared")
    assert not run.out


def _error(text: str) -> str:
    import tomllib

    with pytest.raises(ConfigError) as info:
        parse_config(tomllib.loads(textwrap.dedent(text)), "g.toml")
    return str(info.value)


def test_a_process_key_implies_zenoh_and_refuses_the_local_transport() -> None:
    config = parse_config({"nodes": [{"use": "m:A"}, {"use": "m:B", "process": "vision"}]}, "g.toml")
    assert config.runtime.transport == "zenoh"
    assert config.child_processes == ("vision",)
    assert config.processes["vision"].restart == "on-failure"
    assert _error("""
        [runtime]
        transport = "local"
        [[nodes]]
        use = "m:B"
        process = "vision"
        """) == (
        'g.toml: runtime.transport: a [[nodes]] process key puts a node in another process, which needs '
        'transport = "zenoh" (or no transport key), found "local"'
    )


def test_bad_process_tables_are_one_line_errors() -> None:
    node = '[[nodes]]\nuse = "m:B"\nprocess = "vision"\n'
    assert _error('[[nodes]]\nuse = "m:B"\nprocess = "2d vision"\n') == (
        "g.toml: nodes[0].process: expected a process name of letters, digits, '_' and '-' starting with "
        'a letter (at most 63 characters), found "2d vision"'
    )
    assert _error(node + "[processes.visoin]\n") == (
        'g.toml: processes.visoin: expected a process named by a [[nodes]] process key ("vision"), '
        'found "visoin" (did you mean "vision"?)'
    )
    assert _error(node + "[processes.vision]\nrestarts = 3\n").startswith(
        'g.toml: processes.vision.restarts: unknown key, did you mean "restart"?'
    )
    assert _error(node + '[processes.vision]\nrestart = "sometimes"\n') == (
        'g.toml: processes.vision.restart: expected "no", "on-failure" or "always", found "sometimes"'
    )
    assert _error(node + "[processes.vision]\nmax_restarts = -1\n") == (
        "g.toml: processes.vision.max_restarts: expected an integer >= 0, found -1"
    )
    assert _error(node + "[processes.main]\n").startswith('g.toml: processes.main: expected the name of a child process')


async def test_the_multiprocess_example_runs_its_driver_in_a_child() -> None:
    example = Path(__file__).resolve().parents[2] / "examples" / "multiprocess.toml"
    run = await Run.start(example, "--duration", "3")
    try:
        status = await run.finish()
    finally:
        run.kill()
    assert status == 0, "\n".join(run.err)
    summary = next(line for line in run.out if line.startswith("imu_monitor: received "))
    assert int(summary.split()[2]) > 0
    assert any(line.startswith("[driver] ran ") for line in run.out)
