"""The iceoryx2 data path prototype (issue 27): images between two aiorobot processes through a sample
loaned from iceoryx2's shared memory, discovery on zenoh; a publisher killed with SIGKILL leaves the
receiver running, and a new publisher on the same service delivers again."""

from __future__ import annotations

import contextlib
import os
import signal
from collections.abc import AsyncIterator
from typing import Any

import numpy as np
import pytest

from aiorobot import Node, Runtime
from aiorobot.msgs import serialize
from aiorobot.msgs._cdr_gen import build_parts_serializer
from aiorobot.msgs.geometry_msgs import Twist, Vector3
from aiorobot.msgs.sensor_msgs import Image, PointCloud2, PointField
from aiorobot.transport import ZenohTransport
from aiorobot.transport._iceoryx2 import BORROW_MAX, unavailable

from ._helpers import Child, spawn, wait_until

pytestmark = pytest.mark.skipif(unavailable() is not None, reason=str(unavailable()))

# TOPIC, and SERVICE: an explicit sender on that service, or None: the transport's own (iceoryx2_topics)
CAMERA = """
import numpy as np
from aiorobot.msgs.sensor_msgs import Image
from aiorobot.transport._iceoryx2 import Iceoryx2Sender
async def main(rt):
    node = Node("camera")
    rt.add_node(node)
    pub = node.create_publisher(Image, TOPIC, 10)
    sender = SERVICE and Iceoryx2Sender(rt.transport, Image, TOPIC, SERVICE, max_bytes=320 * 240 * 3 + 1024)
    say("ready")
    reader = await stdin_lines()
    while line := (await reader.readline()).decode().strip():
        first, count = map(int, line.split())
        for i in range(first, first + count):
            pixels = np.random.default_rng(i).integers(0, 256, 320 * 240 * 3, dtype=np.uint8)
            msg = Image(height=240, width=320, encoding="rgb8", step=960, data=pixels)
            msg.header.frame_id = str(i)
            pub.publish(msg)
        sent = (sender or rt.transport._iox_senders[(TOPIC, "sensor_msgs/msg/Image")]).sent
        say("sent", sent, rt.transport.statistics().sent)
"""


def _pixels(i: int) -> np.ndarray:
    return np.random.default_rng(i).integers(0, 256, 320 * 240 * 3, dtype=np.uint8)


def _root(a: np.ndarray) -> object:
    base: object = a
    while isinstance(base, np.ndarray) and base.base is not None:
        base = base.base
    return base.obj if isinstance(base, memoryview) else base


def _iceoryx2_files() -> set[str]:
    return {f for folder in ("/dev/shm", "/tmp/iceoryx2") if os.path.isdir(folder) for f in _walk(folder) if "iox2" in f}


def _walk(folder: str) -> list[str]:
    return [os.path.join(d, f) for d, _, files in os.walk(folder) for f in files]


async def _camera(port: int, service: str) -> Child:
    child = await spawn(f"TOPIC = '/image'\nSERVICE = {service!r}\n" + CAMERA, port)
    await child.expect("ready")
    return child


@contextlib.asynccontextmanager
async def _viewer(port: int, service: str) -> AsyncIterator[tuple[Runtime, list[Image], Any]]:
    """A runtime here receiving /image over iceoryx2 into ``images``."""
    from aiorobot.transport._iceoryx2 import Iceoryx2Receiver

    async with Runtime(transport=ZenohTransport(connect=[f"tcp/127.0.0.1:{port}"]), handle_signals=False) as rt:
        receiver = Iceoryx2Receiver(rt.transport, Image, "/image", service)
        images: list[Image] = []
        rt.add_node(Node("viewer")).create_subscription(Image, "/image", images.append, 10)
        yield rt, images, receiver


async def _frames(child: Child, rt: Runtime, images: list[Image], first: int, count: int) -> list[Image]:
    """Have the camera publish frames ``first..first+count-1`` back to back; what arrived of them."""
    await wait_until(lambda: len(rt.graph.publishers_of("/image")) == 1)  # zenoh discovery: its GID known
    before = len(images)
    child.send(f"{first} {count}")
    sent, over_zenoh = map(int, (await child.expect("sent")).split()[1:])
    assert over_zenoh == 0  # no zenoh subscriber for /image here: the zenoh publisher sent nothing
    await wait_until(lambda: len(images) >= before + count)
    return images[before:]


def _check(frames: list[Image], first: int) -> None:
    assert [int(m.header.frame_id) for m in frames] == list(range(first, first + len(frames)))
    for m in frames:
        assert (m.height, m.width, m.encoding) == (240, 320, "rgb8")
        assert np.array_equal(m.data, _pixels(int(m.header.frame_id)))


def test_the_parts_serializer_joins_to_the_serializer_s_bytes() -> None:
    for msg in (
        Twist(linear=Vector3(x=1.5)),
        Image(height=2, width=3, encoding="rgb8", step=9, data=np.arange(18, dtype=np.uint8)),
        PointCloud2(fields=[PointField(name="x", offset=0, datatype=7, count=1)], data=np.arange(7, dtype=np.uint8)),
    ):
        parts, size = build_parts_serializer(type(msg))(msg)
        assert b"".join(parts) == serialize(msg) and size == len(serialize(msg))


async def test_images_from_another_process_arrive_intact_in_order_as_views_of_the_sample(router_port: int) -> None:
    service = f"aiorobot/test/{router_port}/image"
    async with _viewer(router_port, service) as (rt, images, receiver):
        child = await _camera(router_port, service)
        try:
            frames = await _frames(child, rt, images, 0, 6)
            _check(frames, 0)
            data = frames[0].data
            assert not data.flags.writeable and not data.flags.owndata
            assert getattr(_root(data), "_sample", None) is not None  # decoded in the loaned sample, not copied
            assert frames[0] is not frames[1] and receiver.copied == 0
            # published into the bus as the camera's publisher (its GID in the payload), not an unknown one
            assert receiver._injector is not None and receiver._injector.node_name.endswith("camera")
            # all kept alive (the list holds them): past BORROW_MAX - 1 samples held, messages are copied out
            more = await _frames(child, rt, images, 6, 6)
            _check(more, 6)
            assert receiver.copied == 12 - (BORROW_MAX - 1)
            assert getattr(_root(more[-1].data), "_sample", None) is None and not more[-1].data.flags.writeable
            _check(frames, 0)
        finally:
            await child.stop()
        assert child.proc.stderr is not None
        err = (await child.proc.stderr.read()).decode()
        assert "No config file was loaded" not in err, err  # iceoryx2's start-up notice, said by every process


async def test_a_publisher_killed_with_sigkill_leaves_the_receiver_running_and_a_new_one_delivers(router_port: int) -> None:
    service = f"aiorobot/test/{router_port}/kill"
    async with _viewer(router_port, service) as (rt, images, receiver):
        before = _iceoryx2_files()
        first = await _camera(router_port, service)
        segments = {f for f in _iceoryx2_files() - before if f.endswith(".data")}  # its data segment
        assert segments
        try:
            kept = await _frames(first, rt, images, 0, 3)
            first.proc.send_signal(signal.SIGKILL)
            assert await first.proc.wait() == -signal.SIGKILL
        finally:
            await first.stop()
        await wait_until(lambda: not rt.graph.publishers_of("/image"))  # zenoh saw it go
        _check(kept, 0)  # the frames it sent are still whole: their samples outlive their publisher
        assert receiver._thread.is_alive()
        assert segments <= _iceoryx2_files()  # what the killed process held stays until someone cleans up
        second = await _camera(router_port, service)
        try:
            _check(await _frames(second, rt, images, 10, 4), 10)
            _check(kept, 0)
            assert not segments & _iceoryx2_files()  # the new publisher's node released the dead one's memory
        finally:
            await second.stop()
        assert rt.transport.statistics().dropped == 0 and receiver._thread.is_alive()


async def test_a_malformed_sample_is_dropped_with_one_warning_and_the_next_one_arrives(router_port: int, caplog: Any) -> None:
    import ctypes

    import iceoryx2 as iox2

    service = f"aiorobot/test/{router_port}/bad"
    async with _viewer(router_port, service) as (rt, images, receiver):
        node = iox2.NodeBuilder.new().create(iox2.ServiceType.Ipc)
        data = node.service_builder(iox2.ServiceName.new(service)).publish_subscribe(iox2.Slice[ctypes.c_uint8]).open_or_create()
        publisher = data.publisher_builder().initial_max_slice_len(1 << 16).create()
        notifier = node.service_builder(iox2.ServiceName.new(service + "/event")).event().open_or_create().notifier_builder().create()
        good = Image(height=4, width=4, encoding="mono8", step=4, data=np.arange(16, dtype=np.uint8))
        for payload in (bytes(16) + b"\x07\x07\x00\x00" + bytes(40), bytes(16) + serialize(good)):
            sample = publisher.loan_slice_uninit(len(payload))
            ctypes.memmove(sample.payload_ptr, payload, len(payload))
            sample.assume_init().send()
            notifier.notify()
        await wait_until(lambda: bool(images))
        assert np.array_equal(images[0].data, good.data) and len(images) == 1  # from an unknown GID: delivered all the same
        assert rt.transport.statistics().drop_reasons == {"cdr": 1}
        assert [r.getMessage() for r in caplog.records if "iceoryx2" in r.getMessage() and "malformed CDR" in r.getMessage()]
        assert receiver._thread.is_alive()


async def test_a_topic_listed_in_iceoryx2_topics_goes_over_iceoryx2_between_plain_publishers_and_subscriptions(
    router_port: int, monkeypatch: Any
) -> None:
    """ZenohTransport(iceoryx2_topics=) / AIOROBOT_ICEORYX2_TOPICS: plain create_publisher and
    create_subscription in two processes; the service is agreed from domain, topic and type."""
    from aiorobot.transport._iceoryx2 import Iceoryx2Receiver

    topic = f"/image_{router_port}"  # (iceoryx2 services are host-wide: one per test run)
    monkeypatch.setenv("AIOROBOT_ICEORYX2_TOPICS", f"/other, {topic}")  # the child reads it too
    child = await spawn(f"TOPIC = {topic!r}\nSERVICE = None\n" + CAMERA, router_port)
    try:
        await child.expect("ready")
        transport = ZenohTransport(connect=[f"tcp/127.0.0.1:{router_port}"])
        assert transport.iceoryx2_topics == {"/other", topic}
        async with Runtime(transport=transport, handle_signals=False) as rt:
            images: list[Image] = []
            rt.add_node(Node("viewer")).create_subscription(Image, topic, images.append, 10)
            assert isinstance(transport._inbound[(topic, "sensor_msgs/msg/Image")], Iceoryx2Receiver)
            await wait_until(lambda: len(rt.graph.publishers_of(topic)) == 1)
            child.send("0 5")
            sent, over_zenoh = map(int, (await child.expect("sent")).split()[1:])
            await wait_until(lambda: len(images) >= 5)
            assert sent == 5 and over_zenoh == 0  # each image once, over iceoryx2
            _check(images, 0)
            assert getattr(_root(images[0].data), "_sample", None) is not None
    finally:
        await child.stop()


async def test_iceoryx2_topics_without_iceoryx2_is_one_config_error_before_anything_opens(monkeypatch: Any) -> None:
    from aiorobot._core._errors import ConfigError
    from aiorobot.transport import _iceoryx2

    monkeypatch.setattr(_iceoryx2, "unavailable", lambda: "iceoryx2 is not installed (pip install iceoryx2)")
    with pytest.raises(ConfigError, match=r"/cam over iceoryx2: expected the iceoryx2 package, found none \(iceoryx2 is not"):
        async with Runtime(transport=ZenohTransport(iceoryx2_topics=["cam"]), handle_signals=False):
            pass


async def test_a_sender_with_no_iceoryx2_subscriber_serialises_nothing_until_one_connects(router_port: int) -> None:
    import ctypes

    import iceoryx2 as iox2

    from aiorobot.transport._iceoryx2 import Iceoryx2Sender

    service = f"aiorobot/test/{router_port}/idle"
    async with Runtime(transport=ZenohTransport(connect=[f"tcp/127.0.0.1:{router_port}"]), handle_signals=False) as rt:
        sender = Iceoryx2Sender(rt.transport, Image, "/image", service, max_bytes=320 * 240 * 3 + 1024)
        pub = rt.add_node(Node("camera")).create_publisher(Image, "/image", 5)
        frame = lambda i: Image(height=240, width=320, encoding="rgb8", step=960, data=_pixels(i))  # noqa: E731
        for i in range(3):
            pub.publish(frame(i))
        assert (sender.sent, sender.skipped) == (0, 3)
        node = iox2.NodeBuilder.new().create(iox2.ServiceType.Ipc)
        data = (
            node.service_builder(iox2.ServiceName.new(service))
            .publish_subscribe(iox2.Slice[ctypes.c_uint8])
            .subscriber_max_buffer_size(8)
            .subscriber_max_borrowed_samples(8)
            .open_or_create()
        )
        subscriber = data.subscriber_builder().buffer_size(8).create()
        pub.publish(frame(3))
        assert (sender.sent, sender.skipped) == (1, 3)
        sample = subscriber.receive()
        assert sample is not None and sample.header.number_of_elements > 320 * 240 * 3
        del sample
        subscriber.delete()
        sender.close()
