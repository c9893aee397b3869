"""A received image's pixels are a read-only view into the received bytes, not one more copy (issue 27)."""

from __future__ import annotations

import numpy as np

from aiorobot import Node, Runtime
from aiorobot.msgs import deserialize, serialize
from aiorobot.msgs.sensor_msgs import Image
from aiorobot.transport import ZenohTransport

from ._helpers import spawn, wait_until

CAMERA = """
import numpy as np
from aiorobot.msgs.sensor_msgs import Image
async def main(rt):
    node = Node("camera")
    rt.add_node(node)
    pub = node.create_publisher(Image, "/image", 5)
    pixels = (np.arange(320 * 240 * 3) % 251).astype(np.uint8)
    say("ready")
    reader = await stdin_lines()
    while (await reader.readline()).decode().strip():
        pub.publish(Image(height=240, width=320, encoding="rgb8", step=960, data=pixels))
        say("sent")
"""


def _root(a: np.ndarray) -> object:
    base: object = a
    while isinstance(base, np.ndarray) and base.base is not None:
        base = base.base
    return base


def test_deserialize_view_shares_the_input_and_the_default_copies() -> None:
    pixels = (np.arange(64 * 48 * 3) % 251).astype(np.uint8)
    data = serialize(Image(height=48, width=64, encoding="rgb8", step=192, data=pixels))
    viewed, copied = deserialize(data, Image, view=True), deserialize(data, Image)
    raw = np.frombuffer(data, np.uint8)
    assert np.array_equal(viewed.data, pixels) and np.array_equal(copied.data, pixels)
    assert np.shares_memory(viewed.data, raw) and not viewed.data.flags.writeable
    assert not np.shares_memory(copied.data, raw) and copied.data.flags.writeable


async def test_a_received_image_is_a_read_only_view_into_the_payload(router_port: int) -> None:
    child = await spawn(CAMERA, router_port)
    try:
        await child.expect("ready")
        transport = ZenohTransport(connect=[f"tcp/127.0.0.1:{router_port}"])
        async with Runtime(transport=transport, handle_signals=False) as rt:
            node = rt.add_node(Node("viewer"))
            images: list[Image] = []
            node.create_subscription(Image, "/image", images.append, 5)
            await wait_until(lambda: len(rt.graph.publishers_of("/image")) == 1)
            for _ in range(200):
                child.send("1")
                await child.expect("sent")
                try:
                    await wait_until(lambda: bool(images), timeout_sec=0.5)
                    break
                except TimeoutError:
                    continue
            assert images, "no image arrived"
            data = images[0].data
            assert np.array_equal(data, (np.arange(320 * 240 * 3) % 251).astype(np.uint8))
            assert not data.flags.writeable and not data.flags.owndata
            assert isinstance(_root(data), bytes)  # the payload's bytes, decoded in place
    finally:
        await child.stop()
