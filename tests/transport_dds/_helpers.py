"""The DDS transport tests' parts: a domain id of their own, a bare cyclonedds peer in a child process."""

from __future__ import annotations

import asyncio
import itertools
import json
import os
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

from aiorobot import Runtime
from aiorobot.transport import DdsTransport

__all__ = ["BarePeer", "dds_runtime", "fresh_domain", "wait_until"]

PEER = Path(__file__).with_name("bare_peer.py")
_counter = itertools.count()


def fresh_domain() -> int:
    """A domain id no other test uses at the same time: 10 per xdist worker (gw0 -> 1..10, ...),
    in ROS's 0..101 range, so parallel workers never meet."""
    worker = os.environ.get("PYTEST_XDIST_WORKER", "gw0")
    index = int(worker[2:]) if worker[2:].isdigit() else 0
    return 1 + (index * 10 + next(_counter) % 10) % 100


def dds_env(domain_id: int) -> dict[str, str]:
    env = dict(os.environ)
    env.update(ROS_DOMAIN_ID=str(domain_id), ROS_AUTOMATIC_DISCOVERY_RANGE="LOCALHOST")
    env.pop("CYCLONEDDS_URI", None)
    env.pop("ROS_LOCALHOST_ONLY", None)
    env.pop("ROS_STATIC_PEERS", None)
    return env


def dds_runtime(domain_id: int, **kw: Any) -> Runtime:
    """A runtime on the DDS transport, discovering on localhost only (as ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST)."""
    from aiorobot.transport._dds_wire import discovery_config

    config, _ = discovery_config({"ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST"})
    return Runtime(transport=DdsTransport(domain_id=domain_id, config=config), handle_signals=False, **kw)


async def wait_until(predicate: Callable[[], bool], timeout_sec: float = 20.0) -> None:
    async with asyncio.timeout(timeout_sec):
        while not predicate():
            await asyncio.sleep(0.01)


class BarePeer:
    """``bare_peer.py`` in a child process: one JSON command in, one JSON answer out."""

    def __init__(self, proc: asyncio.subprocess.Process, guid: str) -> None:
        self.proc = proc
        self.guid = guid

    @classmethod
    async def start(cls, domain_id: int) -> BarePeer:
        proc = await asyncio.create_subprocess_exec(
            sys.executable, str(PEER), stdin=asyncio.subprocess.PIPE, stdout=asyncio.subprocess.PIPE,
            stderr=asyncio.subprocess.PIPE, env=dds_env(domain_id),
        )
        first = await cls._line(proc)
        return cls(proc, first["guid"])

    @staticmethod
    async def _line(proc: asyncio.subprocess.Process) -> dict[str, Any]:
        assert proc.stdout is not None
        async with asyncio.timeout(30):
            raw = await proc.stdout.readline()
        if not raw:
            err = await proc.stderr.read() if proc.stderr else b""
            raise AssertionError(f"bare peer exited: {err.decode(errors='replace')[-2000:]}")
        return json.loads(raw)

    async def cmd(self, **command: Any) -> dict[str, Any]:
        assert self.proc.stdin is not None
        self.proc.stdin.write((json.dumps(command) + "\n").encode())
        await self.proc.stdin.drain()
        out = await self._line(self.proc)
        assert "error" not in out, out["error"]
        return out

    async def close(self) -> None:
        if self.proc.returncode is None:
            self.proc.kill()
        await self.proc.wait()

    async def __aenter__(self) -> BarePeer:
        return self

    async def __aexit__(self, *exc: object) -> None:
        await self.close()
