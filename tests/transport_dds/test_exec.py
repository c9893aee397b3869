"""rclpy programs (a talker and a listener in ros2/examples' shape) under ``aiorobot exec --transport dds``,
against a bare cyclonedds peer."""

from __future__ import annotations

import asyncio
import sys
from collections.abc import AsyncIterator
from contextlib import asynccontextmanager
from pathlib import Path

from aiorobot.msgs import type_hash
from aiorobot.msgs.std_msgs import String

from ._helpers import BarePeer, dds_env

PROGRAMS = Path(__file__).with_name("programs")


@asynccontextmanager
async def _exec(domain_id: int, program: str) -> AsyncIterator[asyncio.subprocess.Process]:
    proc = await asyncio.create_subprocess_exec(
        sys.executable, "-m", "aiorobot.cli", "exec", "--transport", "dds", str(PROGRAMS / program),
        stdout=asyncio.subprocess.PIPE, stderr=asyncio.subprocess.STDOUT, env=dds_env(domain_id),
    )
    try:
        yield proc
    finally:
        if proc.returncode is None:
            proc.kill()
        await proc.wait()


async def _line_with(proc: asyncio.subprocess.Process, text: str) -> str:
    assert proc.stdout is not None
    seen = []
    async with asyncio.timeout(30):
        while True:
            raw = await proc.stdout.readline()
            if not raw:
                raise AssertionError(f"the program ended without printing {text!r}: {b''.join(seen).decode()[-2000:]}")
            seen.append(raw)
            if text in raw.decode():
                return raw.decode()


async def test_an_rclpy_talker_under_exec_reaches_a_bare_reader(peer: BarePeer, domain_id: int) -> None:
    await peer.cmd(op="reader", id="r", topic="rt/chatter", type="String")
    async with _exec(domain_id, "talker.py") as proc:
        await _line_with(proc, 'Publishing: "Hello World: 0"')
        samples = (await peer.cmd(op="take", id="r", n=3, timeout=30))["samples"]
        info = await peer.cmd(op="nodes", expect="/talker")
    texts = [s["data"] for s in samples]
    assert len(texts) >= 3 and all(t.startswith("Hello World: ") for t in texts)
    numbers = [int(t.rsplit(" ", 1)[1]) for t in texts]
    assert numbers == sorted(numbers)
    assert any(n["name"] == "/talker" for nodes in info["participants"].values() for n in nodes)


async def test_an_rclpy_listener_under_exec_hears_a_bare_writer(peer: BarePeer, domain_id: int) -> None:
    await peer.cmd(op="writer", id="w", topic="rt/chatter", type="String", hash=type_hash(String))
    async with _exec(domain_id, "listener.py") as proc:
        assert (await peer.cmd(op="matched", id="w", timeout=30))["matched"]
        await peer.cmd(op="write", id="w", type="String", value={"data": "from bare DDS"})
        line = await _line_with(proc, "I heard")
    assert 'I heard: "from bare DDS"' in line
