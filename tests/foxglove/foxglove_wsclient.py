"""A Foxglove WebSocket protocol client for the tests (the `websockets` package), written from the
protocol's specification: JSON ops one way and the other, binary frames by opcode.

Every frame the server sends is kept, so a test waits for what it expects without losing what
came before it.
"""

from __future__ import annotations

import asyncio
import json
import struct
from collections.abc import Callable
from typing import Any

import websockets

#: foxglove-sdk 0.30 accepts only this subprotocol name (see docs/foxglove.md)
SUBPROTOCOL = "foxglove.sdk.v1"

MESSAGE_DATA, TIME, SERVICE_RESPONSE, ASSET_RESPONSE = 0x01, 0x02, 0x03, 0x04
CLIENT_MESSAGE_DATA = 0x01


class FoxgloveClient:
    """``async with FoxgloveClient(port) as c:``; ``await c.wait_op("advertise")``; ``c.binary``."""

    def __init__(self, port: int) -> None:
        self.url = f"ws://127.0.0.1:{port}"
        self.ops: list[dict[str, Any]] = []
        self.binary: list[bytes] = []
        self._changed = asyncio.Event()
        self._ws: Any = None
        self._reader: asyncio.Task[None] | None = None

    async def __aenter__(self) -> FoxgloveClient:
        self._ws = await websockets.connect(self.url, subprotocols=[SUBPROTOCOL], max_size=None)
        self._reader = asyncio.create_task(self._read())
        return self

    async def __aexit__(self, *exc: object) -> None:
        assert self._reader is not None
        self._reader.cancel()
        await self._ws.close()

    async def _read(self) -> None:
        try:
            async for frame in self._ws:
                if isinstance(frame, str):
                    self.ops.append(json.loads(frame))
                else:
                    self.binary.append(bytes(frame))
                self._changed.set()
        except websockets.ConnectionClosed:
            pass

    async def until(self, found: Callable[[], Any], timeout: float = 20.0) -> Any:
        """Wait until ``found()`` returns something true (checked at each frame); return it."""
        async with asyncio.timeout(timeout):
            while True:
                value = found()
                if value:
                    return value
                self._changed.clear()
                await self._changed.wait()

    async def wait_op(self, op: str, where: Callable[[dict[str, Any]], bool] = lambda d: True, timeout: float = 20.0) -> dict[str, Any]:
        return await self.until(lambda: next((d for d in self.ops if d.get("op") == op and where(d)), None), timeout)

    async def send(self, doc: dict[str, Any]) -> None:
        await self._ws.send(json.dumps(doc))

    async def channel(self, topic: str) -> dict[str, Any]:
        """The server's advertised channel for ``topic`` (waits for it)."""
        def find() -> Any:
            for d in self.ops:
                if d.get("op") == "advertise":
                    for c in d["channels"]:
                        if c["topic"] == topic:
                            return c
            return None

        return await self.until(find)

    async def advertise(self, channel_id: int, topic: str, schema_name: str, encoding: str = "cdr") -> None:
        await self.send({"op": "advertise", "channels": [
            {"id": channel_id, "topic": topic, "encoding": encoding, "schemaName": schema_name, "schemaEncoding": "ros2msg"}]})

    async def publish(self, channel_id: int, payload: bytes) -> None:
        await self._ws.send(struct.pack("<BI", CLIENT_MESSAGE_DATA, channel_id) + payload)

    def statuses(self, level: int | None = None) -> list[dict[str, Any]]:
        return [d for d in self.ops if d.get("op") == "status" and (level is None or d["level"] == level)]

    def frames(self, opcode: int) -> list[bytes]:
        return [f for f in self.binary if f[0] == opcode]
