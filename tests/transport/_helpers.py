"""Real zenoh on loopback for the transport tests: a router, peer runtimes and child processes."""

from __future__ import annotations

import asyncio
import os
import socket
import sys
import textwrap
from collections.abc import Callable
from typing import Any

from aiorobot import Runtime
from aiorobot.bench._zenoh import open_router  # the bench's: a router on loopback, multicast scouting off
from aiorobot.transport import ZenohTransport

__all__ = ["Child", "free_port", "open_router", "peer_env", "peer_runtime", "spawn", "wait_until"]


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def peer_env(folder: Any, port: int) -> dict[str, str]:
    """The environment of an ``aiorobot`` command run as a peer of the router on ``port`` (a
    session config file written into ``folder``, multicast scouting off)."""
    conf = folder / "zenoh.json5"
    conf.write_text('{ mode: "peer", connect: { endpoints: ["tcp/127.0.0.1:%d"] }, listen: { endpoints: ["tcp/127.0.0.1:0"] },'
                    ' scouting: { multicast: { enabled: false } } }' % port)
    return {k: v for k, v in os.environ.items() if k != "ZENOH_CONFIG_OVERRIDE"} | {"ZENOH_SESSION_CONFIG_URI": str(conf)}


def peer_runtime(port: int, *, domain_id: int = 0, **kw: Any) -> Runtime:
    transport = ZenohTransport(domain_id=domain_id, connect=[f"tcp/127.0.0.1:{port}"])
    return Runtime(transport=transport, handle_signals=False, **kw)


async def wait_until(predicate: Callable[[], bool], timeout_sec: float = 20.0) -> None:
    async with asyncio.timeout(timeout_sec):
        while not predicate():
            await asyncio.sleep(0.01)


class Child:
    """A Python child process running ``code`` in a zenoh runtime; talks through stdout lines."""

    def __init__(self, proc: asyncio.subprocess.Process) -> None:
        self.proc = proc
        self.lines: list[str] = []

    async def expect(self, prefix: str, timeout_sec: float = 20.0) -> str:
        assert self.proc.stdout is not None
        async with asyncio.timeout(timeout_sec):
            while True:
                raw = await self.proc.stdout.readline()
                if not raw:
                    err = await self.proc.stderr.read() if self.proc.stderr else b""
                    raise AssertionError(f"child exited before printing {prefix!r}: {err.decode()[-2000:]}")
                line = raw.decode().rstrip("\n")
                self.lines.append(line)
                if line.startswith(prefix):
                    return line

    def send(self, line: str) -> None:
        assert self.proc.stdin is not None
        self.proc.stdin.write((line + "\n").encode())

    async def stop(self) -> int:
        if self.proc.returncode is None:
            self.proc.kill()
        return await self.proc.wait()


PRELUDE = """
import asyncio, sys
import aiorobot
from aiorobot import *
from aiorobot.transport import ZenohTransport

def say(*parts):
    print(*parts, flush=True)

async def stdin_lines():
    loop = asyncio.get_running_loop()
    reader = asyncio.StreamReader()
    await loop.connect_read_pipe(lambda: asyncio.StreamReaderProtocol(reader), sys.stdin)
    return reader
"""


async def spawn(code: str, port: int, *, domain_id: int = 0, env: dict[str, str | None] | None = None) -> Child:
    """Run ``code`` (an ``async def main(rt)`` body's module) in a child with a zenoh runtime
    (``env``: variables set, or unset when None, over this process's environment)."""
    script = PRELUDE + textwrap.dedent(code) + textwrap.dedent(f"""
        async def _entry():
            async with Runtime(transport=ZenohTransport(domain_id={domain_id}, connect=["tcp/127.0.0.1:{port}"]), handle_signals=False) as rt:
                await main(rt)
        aiorobot.run(_entry())
        """)
    environ = dict(os.environ)
    environ.pop("ZENOH_CONFIG_OVERRIDE", None)
    for name, value in (env or {}).items():
        if value is None:
            environ.pop(name, None)
        else:
            environ[name] = value
    proc = await asyncio.create_subprocess_exec(
        sys.executable, "-c", script,
        stdin=asyncio.subprocess.PIPE, stdout=asyncio.subprocess.PIPE, stderr=asyncio.subprocess.PIPE, env=environ,
    )
    return Child(proc)
