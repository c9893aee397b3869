"""iceoryx2 as the same-host data path of large messages (issue 27, ``iceoryx2_topics``): images
between aiorobot processes through a sample loaned from iceoryx2's shared memory once every remote
subscription is served that way, over zenoh as well for one that is not, delivered once either
way; small messages stay on zenoh; a publisher killed with SIGKILL leaves the receiver running, and
a new publisher delivers."""

from __future__ import annotations

import ctypes
import os
import signal
from typing import Any

import numpy as np
import pytest

from aiorobot import Node, Runtime
from aiorobot.msgs import serialize
from aiorobot.msgs._cdr_gen import build_parts_serializer
from aiorobot.msgs.geometry_msgs import Twist, Vector3
from aiorobot.msgs.sensor_msgs import Image, Imu, LaserScan, PointCloud2, PointField
from aiorobot.msgs.std_msgs import String
from aiorobot.msgs.nav_msgs import OccupancyGrid
from aiorobot.transport import ZenohTransport
from aiorobot.transport._iceoryx2 import BORROW_MAX, HEAD, carries_arrays, unavailable
from aiorobot.transport._wire import pack_attachment

from ._helpers import Child, spawn, wait_until

pytestmark = pytest.mark.skipif(unavailable() is not None, reason=str(unavailable()))

FRAME = """
import numpy as np
from aiorobot.msgs.sensor_msgs import Image
def frame(i, side):
    pixels = np.random.default_rng(i).integers(0, 256, side * side * 3, dtype=np.uint8)
    msg = Image(height=side, width=side, encoding="rgb8", step=side * 3, data=pixels)
    msg.header.frame_id = str(i)
    return msg
"""
# TOPIC: publishes frames on command: "served N" (N remote subscriptions known, all served over
# iceoryx2), "subs N" (N known), "FIRST COUNT SIDE" (frames FIRST.. of SIDE x SIDE pixels)
CAMERA = FRAME + """
async def main(rt):
    node = Node("camera")
    rt.add_node(node)
    pub = node.create_publisher(Image, TOPIC, 10)
    out = rt.transport._outbound[(TOPIC, "sensor_msgs/msg/Image")]
    say("ready")
    reader = await stdin_lines()
    while line := (await reader.readline()).decode().strip():
        cmd, *args = line.split()
        if cmd in ("served", "subs"):
            while pub.get_subscription_count() < int(args[0]) or (cmd == "served" and out.zenoh_needed):
                await asyncio.sleep(0.01)
            say(cmd)
            continue
        first, count, side = map(int, line.split())
        for i in range(first, first + count):
            pub.publish(frame(i, side))
        stats = rt.transport.statistics()
        say("sent", stats.sent, stats.sent_iceoryx2)
"""
# TOPIC: "N" -> "got ID,ID,... RECEIVED_ICEORYX2" once N frames arrived
SINK = """
from aiorobot.msgs.sensor_msgs import Image
async def main(rt):
    got = []
    rt.add_node(Node("sink")).create_subscription(Image, TOPIC, lambda m: got.append(m.header.frame_id), 10)
    say("ready")
    reader = await stdin_lines()
    while line := (await reader.readline()).decode().strip():
        while len(got) < int(line):
            await asyncio.sleep(0.01)
        say("got", ",".join(got), rt.transport.statistics().received_iceoryx2)
"""
SIDE = 160  # 160 x 160 x 3: 77 KB


def _frame(i: int, side: int = SIDE) -> Image:
    pixels = np.random.default_rng(i).integers(0, 256, side * side * 3, dtype=np.uint8)
    msg = Image(height=side, width=side, encoding="rgb8", step=side * 3, data=pixels)
    msg.header.frame_id = str(i)
    return msg


def _root(a: np.ndarray) -> object:
    base: object = a
    while isinstance(base, np.ndarray) and base.base is not None:
        base = base.base
    return base.obj if isinstance(base, memoryview) else base


def _iceoryx2_files() -> set[str]:
    return {f for folder in ("/dev/shm", "/tmp/iceoryx2") if os.path.isdir(folder) for f in _walk(folder) if "iox2" in f}


def _walk(folder: str) -> list[str]:
    return [os.path.join(d, f) for d, _, files in os.walk(folder) for f in files]


def _topic(port: int) -> str:
    return f"/image_{port}"  # (iceoryx2 services are host-wide: one per test run)


async def _child(code: str, port: int, *, iceoryx2: bool = True) -> Child:
    topic = _topic(port)
    env = {"AIOROBOT_ICEORYX2_TOPICS": topic if iceoryx2 else None}
    child = await spawn(f"TOPIC = {topic!r}\n" + code, port, env=env)
    await child.expect("ready")
    return child


def _viewer(port: int) -> Runtime:
    """A runtime here whose transport takes the iceoryx2 path for the test's topic."""
    transport = ZenohTransport(connect=[f"tcp/127.0.0.1:{port}"], iceoryx2_topics=[_topic(port)])
    return Runtime(transport=transport, handle_signals=False)


async def _publish(camera: Child, first: int, count: int, side: int = SIDE) -> tuple[int, int]:
    """Frames ``first..`` from the camera: its totals ``(sent over zenoh, sent over iceoryx2)``."""
    camera.send(f"{first} {count} {side}")
    sent, sent_iox = map(int, (await camera.expect("sent")).split()[1:])
    return sent, sent_iox


def _check(frames: list[Image], first: int, side: int = SIDE) -> None:
    assert [int(m.header.frame_id) for m in frames] == list(range(first, first + len(frames)))
    for m in frames:
        assert (m.height, m.width, m.encoding) == (side, side, "rgb8")
        assert np.array_equal(m.data, _frame(int(m.header.frame_id), side).data)


def test_the_parts_serializer_joins_to_the_serializer_s_bytes() -> None:
    for msg in (
        Twist(linear=Vector3(x=1.5)),
        Image(height=2, width=3, encoding="rgb8", step=9, data=np.arange(18, dtype=np.uint8)),
        PointCloud2(fields=[PointField(name="x", offset=0, datatype=7, count=1)], data=np.arange(7, dtype=np.uint8)),
    ):
        parts, size = build_parts_serializer(type(msg))(msg)
        assert b"".join(parts) == serialize(msg) and size == len(serialize(msg))


def test_the_types_star_selects_carry_an_unbounded_array_of_numbers() -> None:
    assert carries_arrays(Image) and carries_arrays(PointCloud2) and carries_arrays(LaserScan)
    assert carries_arrays(OccupancyGrid)  # (int8[] data)
    assert not carries_arrays(Twist) and not carries_arrays(String)
    assert not carries_arrays(Imu)  # fixed float64[9] covariances only


async def test_images_go_over_iceoryx2_alone_once_the_subscriber_is_served_and_arrive_as_views_of_the_sample(
    router_port: int,
) -> None:
    async with _viewer(router_port) as rt:
        images: list[Image] = []
        rt.add_node(Node("viewer")).create_subscription(Image, _topic(router_port), images.append, 10)
        inbound = rt.transport._inbound[(_topic(router_port), "sensor_msgs/msg/Image")]
        camera = await _child(CAMERA, router_port)
        try:
            camera.send("served 1")
            await camera.expect("served")
            assert await _publish(camera, 0, 6) == (0, 6)  # over iceoryx2 alone: nothing put on zenoh
            await wait_until(lambda: len(images) >= 6)
            _check(images, 0)
            data = images[0].data
            assert not data.flags.writeable and not data.flags.owndata
            assert getattr(_root(data), "_sample", None) is not None  # decoded in the loaned sample, not copied
            # published into the bus as the camera's publisher (its GID in the payload), not an unknown one
            assert inbound._injector is not None and inbound._injector.node_name.endswith("camera")
            # all kept alive (the list holds them): past BORROW_MAX - 1 samples held, messages are copied out
            assert await _publish(camera, 6, 6) == (0, 12)
            await wait_until(lambda: len(images) >= 12)
            _check(images, 0)
            assert inbound.iox.copied == 12 - (BORROW_MAX - 1)
            assert getattr(_root(images[-1].data), "_sample", None) is None and not images[-1].data.flags.writeable
            # a small message of the topic (under shm_threshold) goes over zenoh
            assert await _publish(camera, 12, 2, side=4) == (2, 12)
            await wait_until(lambda: len(images) >= 14)
            _check(images[12:], 12, side=4)
            stats = rt.transport.statistics()
            assert (stats.received_iceoryx2, stats.received, stats.dropped) == (12, 2, 0)
        finally:
            await camera.stop()
        assert camera.proc.stderr is not None
        err = (await camera.proc.stderr.read()).decode()
        assert "No config file was loaded" not in err, err  # iceoryx2's start-up notice, said by every process


async def test_a_subscriber_without_the_path_gets_every_image_over_zenoh_and_the_served_one_each_once(
    router_port: int,
) -> None:
    """A third process, without the topic in iceoryx2_topics: the camera puts on zenoh too; the
    viewer gets each image both ways and delivers it once."""
    async with _viewer(router_port) as rt:
        images: list[Image] = []
        rt.add_node(Node("viewer")).create_subscription(Image, _topic(router_port), images.append, 10)
        sink = await _child(SINK, router_port, iceoryx2=False)
        camera = await _child(CAMERA, router_port)
        try:
            camera.send("subs 2")
            await camera.expect("subs")
            assert await _publish(camera, 0, 8) == (8, 8)  # each image both ways
            sink.send("8")
            ids, sink_iox = (await sink.expect("got")).split()[1:]
            assert ids == ",".join(map(str, range(8))) and sink_iox == "0"
            await wait_until(lambda: rt.transport.statistics().received >= 8)  # the zenoh copies came too
            await wait_until(lambda: len(images) >= 8)
            stats = rt.transport.statistics()
            assert stats.received_iceoryx2 == 8 and stats.dropped == 0
            _check(images, 0)
            assert len(images) == 8  # once each
        finally:
            await camera.stop()
            await sink.stop()


async def test_a_publisher_killed_with_sigkill_leaves_the_receiver_running_and_a_new_one_delivers(router_port: int) -> None:
    async with _viewer(router_port) as rt:
        images: list[Image] = []
        rt.add_node(Node("viewer")).create_subscription(Image, _topic(router_port), images.append, 10)
        inbound = rt.transport._inbound[(_topic(router_port), "sensor_msgs/msg/Image")]
        before = _iceoryx2_files()
        first = await _child(CAMERA, router_port)
        try:
            first.send("served 1")
            await first.expect("served")
            segments = {f for f in _iceoryx2_files() - before if f.endswith(".data")}  # its data segment
            assert segments
            assert await _publish(first, 0, 3) == (0, 3)
            await wait_until(lambda: len(images) >= 3)
            first.proc.send_signal(signal.SIGKILL)
            assert await first.proc.wait() == -signal.SIGKILL
        finally:
            await first.stop()
        await wait_until(lambda: not rt.graph.publishers_of(_topic(router_port)))  # zenoh saw it go
        _check(images, 0)  # the frames it sent are still whole: their samples outlive their publisher
        assert inbound.iox._thread.is_alive()
        second = await _child(CAMERA, router_port)
        try:
            second.send("served 1")
            await second.expect("served")
            assert await _publish(second, 10, 4) == (0, 4)
            await wait_until(lambda: len(images) >= 7)
            _check(images[3:], 10)
            _check(images[:3], 0)
            assert not segments & _iceoryx2_files()  # what the dead process held was released
        finally:
            await second.stop()
        assert rt.transport.statistics().dropped == 0 and inbound.iox._thread.is_alive()


async def test_a_subscriber_killed_with_sigkill_is_released_and_the_publisher_goes_on(router_port: int, caplog: Any) -> None:
    caplog.set_level("INFO", logger="aiorobot.transport")
    async with _viewer(router_port) as rt:
        pub = rt.add_node(Node("camera")).create_publisher(Image, _topic(router_port), 10)
        out = rt.transport._outbound[(_topic(router_port), "sensor_msgs/msg/Image")]
        sink = await _child(SINK, router_port)
        await wait_until(lambda: pub.get_subscription_count() == 1 and not out.zenoh_needed)
        for i in range(3):
            pub.publish(_frame(i))
        sink.send("3")
        assert (await sink.expect("got")).split()[1:] == ["0,1,2", "3"]
        sink.proc.send_signal(signal.SIGKILL)
        await sink.proc.wait()
        await wait_until(lambda: pub.get_subscription_count() == 0)
        await wait_until(lambda: not out.iox.wanted(), 5)  # its iceoryx2 ports were released when its token went
        for i in range(3, 12):  # more than its buffer held: nothing is loaned to the dead process
            pub.publish(_frame(i))
        again = await _child(SINK, router_port)
        try:
            await wait_until(lambda: pub.get_subscription_count() == 1 and not out.zenoh_needed)
            for i in range(20, 23):
                pub.publish(_frame(i))
            again.send("3")
            assert (await again.expect("got")).split()[1:] == ["20,21,22", "3"]
            said = [r.getMessage() for r in caplog.records if r.getMessage().startswith("iceoryx2_topics: large messages")]
        finally:
            await again.stop()
        stats = rt.transport.statistics()
        assert stats.sent_iceoryx2 == 6 and stats.dropped == 0
        alone = f"iceoryx2_topics: large messages on {_topic(router_port)} go over iceoryx2 alone (1 subscribing processes)"
        # the first sink, then the second one; "over zenoh too" between, as a sink's subscription is
        # known before its iceoryx2 input, or the dead one's input went before its subscription
        assert said[-1] == alone and said.count(alone) == 2, said


async def test_images_the_receiver_was_too_slow_for_are_counted_as_lost_once_newer_ones_came(
    router_port: int, caplog: Any
) -> None:
    """iceoryx2 keeps the newest 8 samples for a subscriber that falls behind. The frames it lost
    leave gaps in the camera's sequence numbers; as an iceoryx2 topic's messages may come either
    way and out of order, a missing one is counted lost once ``WINDOW`` newer ones came."""
    import sys
    import time

    from aiorobot.transport._iceoryx2 import BUFFER_SIZE
    from aiorobot.transport._zenoh import WINDOW

    side = 32  # 3 KB: over iceoryx2 (shm_threshold 2 KiB), cheap to send many of
    async with _viewer(router_port) as rt:
        images: list[Image] = []
        rt.add_node(Node("viewer")).create_subscription(Image, _topic(router_port), images.append, 100)
        camera = await _child(CAMERA, router_port)
        try:
            camera.send("served 1")
            await camera.expect("served")
            assert await _publish(camera, 0, 1, side) == (0, 1)
            await wait_until(lambda: len(images) == 1)
            # this process holds the GIL while the camera sends 40 frames: its iceoryx2 thread cannot
            # take them, and iceoryx2 keeps the newest BUFFER_SIZE
            interval = sys.getswitchinterval()
            sys.setswitchinterval(30.0)
            try:
                camera.send(f"1 40 {side}")
                assert camera.proc.stdin is not None
                await camera.proc.stdin.drain()
                end = time.monotonic() + 2.0
                while time.monotonic() < end:
                    pass
            finally:
                sys.setswitchinterval(interval)
            await camera.expect("sent")
            await wait_until(lambda: len(images) >= 1 + BUFFER_SIZE)
            received = len(images) - 1
            assert received < 40
            # frames that arrive whole, a few at a time, until the window has moved past the lost ones
            first = 41
            while first < 41 + WINDOW:
                await _publish(camera, first, 4, side)
                await wait_until(lambda: len(images) >= received + 1 + (first + 4 - 41))
                first += 4
            await rt.settle()
            stats = rt.transport.statistics()
            assert stats.drop_reasons.get("lost") == 40 - received
            said = [r.getMessage() for r in caplog.records if "never arrived" in r.getMessage()]
            assert said and f"{BUFFER_SIZE} over iceoryx2" in said[0]
            assert [int(m.header.frame_id) for m in images] == sorted(int(m.header.frame_id) for m in images)
        finally:
            await camera.stop()


async def test_one_process_publishing_and_subscribing_sends_nothing_to_itself(router_port: int) -> None:
    async with _viewer(router_port) as rt:
        node = rt.add_node(Node("both"))
        images: list[Image] = []
        node.create_subscription(Image, _topic(router_port), images.append, 10)
        pub = node.create_publisher(Image, _topic(router_port), 10)
        out = rt.transport._outbound[(_topic(router_port), "sensor_msgs/msg/Image")]
        assert out.iox.own == 1 and not out.iox.wanted()  # its own input is no reason to serialise
        for i in range(3):
            pub.publish(_frame(i))
        await wait_until(lambda: len(images) >= 3)
        stats = rt.transport.statistics()
        assert (stats.sent_iceoryx2, stats.received_iceoryx2, len(images)) == (0, 0, 3)


async def test_a_malformed_sample_is_dropped_with_one_warning_and_the_next_one_arrives(router_port: int, caplog: Any) -> None:
    import iceoryx2 as iox2

    async with _viewer(router_port) as rt:
        images: list[Image] = []
        rt.add_node(Node("viewer")).create_subscription(Image, _topic(router_port), images.append, 10)
        service = rt.transport._iceoryx2_service(_topic(router_port), rt.transport._hash(Image))
        node = iox2.NodeBuilder.new().create(iox2.ServiceType.Ipc)
        data = node.service_builder(iox2.ServiceName.new(service)).publish_subscribe(iox2.Slice[ctypes.c_uint8]).open_or_create()
        publisher = data.publisher_builder().initial_max_slice_len(1 << 16).create()
        notifier = node.service_builder(iox2.ServiceName.new(service + "/event")).event().open_or_create().notifier_builder().create()
        good = Image(height=4, width=4, encoding="mono8", step=4, data=np.arange(16, dtype=np.uint8))
        head = pack_attachment(1, 0, bytes(range(16))).ljust(HEAD, b"\0")
        for payload in (head + b"\x07\x07\x00\x00" + bytes(40), bytes(HEAD), head + serialize(good)):
            sample = publisher.loan_slice_uninit(len(payload))
            ctypes.memmove(sample.payload_ptr, payload, len(payload))
            sample.assume_init().send()
            notifier.notify()
        await wait_until(lambda: bool(images))
        assert np.array_equal(images[0].data, good.data) and len(images) == 1  # from an unknown GID: delivered all the same
        assert rt.transport.statistics().drop_reasons == {"cdr": 2}
        assert [r.getMessage() for r in caplog.records if "iceoryx2" in r.getMessage() and "malformed CDR" in r.getMessage()]
        inbound = rt.transport._inbound[(_topic(router_port), "sensor_msgs/msg/Image")]
        assert inbound.iox._thread.is_alive()


async def test_iceoryx2_topics_without_iceoryx2_is_one_config_error_before_anything_opens(monkeypatch: Any) -> None:
    from aiorobot._core._errors import ConfigError
    from aiorobot.transport import _iceoryx2

    monkeypatch.setattr(_iceoryx2, "unavailable", lambda: "iceoryx2 is not installed (pip install iceoryx2)")
    with pytest.raises(ConfigError, match=r"/cam over iceoryx2: expected the iceoryx2 package, found none \(iceoryx2 is not"):
        async with Runtime(transport=ZenohTransport(iceoryx2_topics=["cam"]), handle_signals=False):
            pass


async def test_a_service_iceoryx2_refuses_leaves_the_topic_on_zenoh_with_one_warning(router_port: int, caplog: Any) -> None:
    import iceoryx2 as iox2

    async with _viewer(router_port) as rt:
        # the topic's service made elsewhere with room for one subscriber, taken: this process cannot join it
        service = rt.transport._iceoryx2_service(_topic(router_port), rt.transport._hash(Image))
        node = iox2.NodeBuilder.new().create(iox2.ServiceType.Ipc)
        data = (
            node.service_builder(iox2.ServiceName.new(service)).publish_subscribe(iox2.Slice[ctypes.c_uint8])
            .max_subscribers(1).open_or_create()
        )
        images: list[Image] = []
        rt.add_node(Node("viewer")).create_subscription(Image, _topic(router_port), images.append, 10)
        assert rt.transport._inbound[(_topic(router_port), "sensor_msgs/msg/Image")].iox is None
        camera = await _child(CAMERA, router_port)
        try:
            camera.send("subs 1")
            await camera.expect("subs")
            assert await _publish(camera, 0, 3) == (3, 0)
            await wait_until(lambda: len(images) >= 3)
            _check(images, 0)
        finally:
            await camera.stop()
        said = [r.getMessage() for r in caplog.records if "iceoryx2_topics: cannot receive" in r.getMessage()]
        assert len(said) == 1 and "it goes over zenoh in this process" in said[0], said
        del data
