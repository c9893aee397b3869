"""Large messages between processes on one host go through zenoh's shared memory; the rest is unchanged."""

from __future__ import annotations

import numpy as np
import pytest

from aiorobot import Node, Runtime
from aiorobot.msgs.geometry_msgs import Twist
from aiorobot.msgs.sensor_msgs import Image
from aiorobot.transport import ZenohTransport

from ._helpers import spawn, wait_until

CAMERA = """
import numpy as np
from aiorobot.msgs.geometry_msgs import Twist, Vector3
from aiorobot.msgs.sensor_msgs import Image
async def main(rt):
    node = Node("camera")
    rt.add_node(node)
    image = node.create_publisher(Image, "/image", 5)
    twist = node.create_publisher(Twist, "/cmd", 5)
    pixels = (np.arange(640 * 480 * 3) % 251).astype(np.uint8)  # a pattern a copy bug would break
    say("ready")
    reader = await stdin_lines()
    while line := (await reader.readline()).decode().strip():
        n = int(line)
        image.publish(Image(height=480, width=640, encoding="rgb8", step=1920, data=np.roll(pixels, n)))
        twist.publish(Twist(linear=Vector3(x=float(n))))
        say("sent", n, rt.transport.statistics().sent_shm)
"""


@pytest.mark.parametrize("receiver_shm", [True, False], ids=["both-on-shm", "receiver-without-shm"])
async def test_an_image_travels_through_shared_memory_and_arrives_intact(router_port: int, receiver_shm: bool) -> None:
    child = await spawn(CAMERA, router_port)
    try:
        await child.expect("ready")
        transport = ZenohTransport(connect=[f"tcp/127.0.0.1:{router_port}"], shared_memory=receiver_shm)
        async with Runtime(transport=transport, handle_signals=False) as rt:
            node = rt.add_node(Node("viewer"))
            images: list[Image] = []
            twists: list[float] = []
            node.create_subscription(Image, "/image", images.append, 5)
            node.create_subscription(Twist, "/cmd", lambda m: twists.append(m.linear.x), 5)
            await wait_until(lambda: len(rt.graph.publishers_of("/image")) == 1)
            n = 0
            while len(images) < 3 or len(twists) < 3:
                n += 1
                child.send(str(n))
                line = await child.expect("sent")
                assert n < 200
            expected = (np.arange(640 * 480 * 3) % 251).astype(np.uint8)
            for img in images:
                k = int(np.argmax(np.asarray(img.data) == expected[0]))  # the roll applied by the sender
                assert (img.height, img.width, img.encoding) == (480, 640, "rgb8")
                assert np.array_equal(np.roll(np.asarray(img.data), -k), expected)
            sent_shm = int(line.split()[-1])
            stats = rt.transport.statistics()
            assert sent_shm >= len(images), line  # the sender put every image from its pool
            if receiver_shm:
                assert stats.received_shm >= len(images)
            else:
                assert stats.received_shm == 0  # zenoh copied it onto the socket for this peer
            assert twists == sorted(twists)  # small messages: the ordinary path, unchanged
    finally:
        await child.stop()


def test_shared_memory_settings_are_checked(monkeypatch: pytest.MonkeyPatch) -> None:
    from aiorobot.transport._zenoh import _env_bytes

    monkeypatch.setenv("ZENOH_SHM_MESSAGE_SIZE_THRESHOLD", "lots")
    with pytest.raises(ValueError, match="ZENOH_SHM_MESSAGE_SIZE_THRESHOLD: expected a size in bytes"):
        _env_bytes("ZENOH_SHM_MESSAGE_SIZE_THRESHOLD", 2048)
    monkeypatch.setenv("ZENOH_SHM_MESSAGE_SIZE_THRESHOLD", "4096")
    assert _env_bytes("ZENOH_SHM_MESSAGE_SIZE_THRESHOLD", 2048) == 4096
