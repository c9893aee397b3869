"""Awaiting messages in tests."""

from __future__ import annotations

import asyncio
from typing import TypeVar

from .._core._node import Node
from .._core._qos import QoSProfile

__all__ = ["wait_for_message"]

M = TypeVar("M")


async def wait_for_message(
    node: Node, msg_type: type[M], topic: str, timeout_sec: float = 5.0, *, qos: QoSProfile | int = 10
) -> M:
    """Return the next message on ``topic`` (as seen by ``node``); ``TimeoutError`` after ``timeout_sec``.

    ``node`` must run on the main loop (the loop the test awaits on).
    """
    if node.executor != "main":
        raise ValueError(
            f"wait_for_message needs a node on the main loop, got {node!r}; add a helper node with executor='main'"
        )
    async with node.subscribe(msg_type, topic, qos) as stream:
        try:
            async with asyncio.timeout(timeout_sec):
                return await anext(stream)
        except TimeoutError:
            raise TimeoutError(
                f"no {getattr(msg_type, '__msgtype__', msg_type)} on {node.resolve_topic_name(topic)} "
                f"within {timeout_sec} s"
            ) from None
