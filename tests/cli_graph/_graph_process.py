"""One graph process per test module: a zenoh router and a child runtime on loopback, shared by
the CLI tests (which run ``python -m aiorobot.cli`` as subprocesses against it)."""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import textwrap
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

from tests.transport._helpers import PRELUDE, free_port, open_router

__all__ = ["GraphProcess", "run_cli", "start_graph"]


@dataclass
class GraphProcess:
    port: int
    proc: subprocess.Popen[str]

    def expect(self, prefix: str) -> str:
        """The next line of the child's stdout starting with ``prefix`` (the test timeout bounds the wait)."""
        assert self.proc.stdout is not None
        while True:
            line = self.proc.stdout.readline()
            if not line:
                assert self.proc.stderr is not None
                self.proc.stderr.seek(0)
                raise AssertionError(f"graph process exited before printing {prefix!r}: {self.proc.stderr.read()[-2000:]}")
            if line.startswith(prefix):
                return line.rstrip("\n")


def start_graph(code: str) -> Iterator[GraphProcess]:
    """A generator for a module-scoped fixture: router + child running ``code``'s ``main(rt)``,
    yielded once the child printed ``ready``; both closed afterwards."""
    port = free_port()
    router: Any = open_router(port)
    script = PRELUDE + textwrap.dedent(code) + textwrap.dedent(f"""
        async def _entry():
            async with Runtime(transport=ZenohTransport(domain_id=0, connect=["tcp/127.0.0.1:{port}"]), handle_signals=False) as rt:
                await main(rt)
        aiorobot.run(_entry())
        """)
    env = dict(os.environ)
    env.pop("ZENOH_CONFIG_OVERRIDE", None)
    # stderr to a file: a pipe nobody reads would block the child once its logs fill the buffer
    errors = tempfile.TemporaryFile("w+")
    proc = subprocess.Popen(
        [sys.executable, "-c", script], stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=errors,
        text=True, env=env,
    )
    proc.stderr = errors
    graph = GraphProcess(port, proc)
    try:
        graph.expect("ready")
        yield graph
    finally:
        proc.kill()
        proc.wait()
        for stream in (proc.stdin, proc.stdout, proc.stderr):
            if stream is not None:
                stream.close()
        router.close()


def run_cli(graph: GraphProcess | None, *argv: str, cwd: str | None = None) -> tuple[int, str, str]:
    """``python -m aiorobot.cli *argv`` (connected to ``graph``): exit status, stdout, stderr."""
    connect = ["--connect", f"tcp/127.0.0.1:{graph.port}"] if graph is not None else []
    proc = subprocess.run(
        [sys.executable, "-m", "aiorobot.cli", *argv, *connect],
        capture_output=True, text=True, timeout=30, cwd=cwd,
    )
    return proc.returncode, proc.stdout, proc.stderr
