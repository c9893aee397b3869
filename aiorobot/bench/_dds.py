"""``aiorobot bench latency`` DDS rows: two processes on loopback, aiorobot's DDS transport against a bare
cyclonedds-python writer -> reader pair measured in the same run.

A child process subscribes, the parent publishes messages stamped with ``time.monotonic_ns()`` (one
clock for every process on a Linux host); the child reports one-way latency (receive minus stamp).
Two bare pairs: cyclonedds-python at its cheapest (CDR bytes handed to ``ddspy_write`` and taken
with ``ddspy_take`` in a listener, no Python (de)serialisation: the floor), and as a program written
with it usually is (``IdlStruct`` samples through ``DataWriter.write`` and ``DataReader.take`` in a
listener). aiorobot's path adds its CDR, the hop to the loop and the subscription's callback.
Discovery is on localhost only, in a domain of its own.
"""

from __future__ import annotations

import asyncio
import os
import struct
import subprocess
import sys
import time
from typing import Any

from ._zenoh import _stats

__all__ = ["run", "table"]


async def _send_images(image: Any, n: int) -> None:
    """Publish ``n`` sender-stamped 640x480x3 images, 10 ms apart, then let the last ones land."""
    import numpy as np

    from ..msgs.sensor_msgs import Image

    data = np.zeros(640 * 480 * 3, dtype=np.uint8)
    for _ in range(n):
        now = time.monotonic_ns()
        msg = Image(height=480, width=640, encoding="rgb8", step=640 * 3, data=data)
        msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(now, 1_000_000_000)
        image.publish(msg)
        await asyncio.sleep(0.01)
    await asyncio.sleep(0.3)


async def _report(child: subprocess.Popen[str]) -> dict[str, Any]:
    """Ask the receiving child for its figures (one JSON line)."""
    import json

    assert child.stdin is not None and child.stdout is not None
    child.stdin.write("report\n")
    child.stdin.flush()
    line = await asyncio.to_thread(child.stdout.readline)
    return json.loads(line)


def _domain() -> int:
    """The domain the two processes meet in: ROS's 215..232 range (rarely used by robots), by pid."""
    return 215 + os.getpid() % 18

_CHILD = r"""
import asyncio, json, struct, sys, time
import aiorobot
from aiorobot import Node, Runtime, QoSProfile, HistoryPolicy
from aiorobot.bench._dds import bare_entities, runtime
from aiorobot.msgs.geometry_msgs import Twist
from aiorobot.msgs.sensor_msgs import Image

async def main():
    lat = {"twist": [], "image": [], "bare_twist": [], "bare_image": [], "typed_twist": [], "typed_image": []}
    async with runtime(int(sys.argv[1])) as rt:
        node = rt.add_node(Node("bench_sink"))
        keep_all = QoSProfile(history=HistoryPolicy.KEEP_ALL)
        node.create_subscription(Twist, "/bench/twist", lambda m: lat["twist"].append(time.monotonic_ns() - int(m.linear.x)), keep_all)
        node.create_subscription(Image, "/bench/image", lambda m: lat["image"].append(
            time.monotonic_ns() - (m.header.stamp.sec * 1_000_000_000 + m.header.stamp.nanosec)), keep_all)
        keep = bare_entities(rt.transport, lat)
        print("ready", flush=True)
        loop = asyncio.get_running_loop()
        reader = asyncio.StreamReader()
        await loop.connect_read_pipe(lambda: asyncio.StreamReaderProtocol(reader), sys.stdin)
        while line := (await reader.readline()).decode().strip():
            if line == "report":
                print(json.dumps({"lat": lat, "received_shm": 0}), flush=True)
                lat = {k: [] for k in lat}
                keep[-1][:] = [lat]

aiorobot.run(main())
"""


def runtime(domain_id: int) -> Any:
    """A runtime on the DDS transport that discovers on localhost only."""
    from .. import Runtime
    from ..transport import DdsTransport
    from ..transport._dds_wire import discovery_config

    config, _ = discovery_config({"ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST"})
    return Runtime(transport=DdsTransport(domain_id=domain_id, config=config), handle_signals=False)


def _types() -> tuple[Any, Any]:
    from ..msgs.geometry_msgs import Twist
    from ..msgs.sensor_msgs import Image
    from ..transport._dds_types import idl_struct

    return idl_struct(Twist), idl_struct(Image)


def _qos() -> Any:
    from cyclonedds.core import Policy, Qos

    return Qos(Policy.Reliability.Reliable(10**9), Policy.History.KeepAll, Policy.DataRepresentation(use_cdrv0_representation=True))


def bare_entities(transport: Any, lat: dict[str, list[int]]) -> list[Any]:
    """The child's bare readers on the transport's participant (plain DDS topics: aiorobot ignores them).
    The returned list keeps them alive; its last item holds the dict the listeners fill."""
    from cyclonedds._clayer import ddspy_take
    from cyclonedds.core import InstanceState, Listener, SampleState, ViewState
    from cyclonedds.sub import DataReader
    from cyclonedds.topic import Topic

    twist_t, image_t = _types()
    target: list[dict[str, list[int]]] = [lat]
    mask = SampleState.Any | ViewState.Any | InstanceState.Any

    def on(key: str, stamp: Any) -> Any:
        def take(reader: Any) -> None:
            now = time.monotonic_ns()
            for data, info in ddspy_take(reader._ref, mask, 64):
                if info.valid_data:  # not the writer going away
                    target[0][key].append(now - stamp(data))
        return take

    twist_stamp = lambda data: int(struct.unpack_from("<d", data, 4)[0])  # noqa: E731 - linear.x
    image_stamp = lambda data: (lambda s, ns: s * 1_000_000_000 + ns)(*struct.unpack_from("<iI", data, 4))  # noqa: E731
    def typed(key: str, stamp: Any) -> Any:
        def take(reader: Any) -> None:
            for sample in reader.take(64):
                if sample.sample_info.valid_data:
                    target[0][key].append(time.monotonic_ns() - stamp(sample))
        return take

    dp = transport._participant
    readers = [
        DataReader(dp, Topic(dp, "bench_bare_twist", twist_t), _qos(), listener=Listener(on_data_available=on("bare_twist", twist_stamp))),
        DataReader(dp, Topic(dp, "bench_bare_image", image_t), _qos(), listener=Listener(on_data_available=on("bare_image", image_stamp))),
        DataReader(dp, Topic(dp, "bench_typed_twist", twist_t), _qos(),
                   listener=Listener(on_data_available=typed("typed_twist", lambda m: int(m.linear.x)))),
        DataReader(dp, Topic(dp, "bench_typed_image", image_t), _qos(), listener=Listener(on_data_available=typed(
            "typed_image", lambda m: m.header.stamp.sec * 1_000_000_000 + m.header.stamp.nanosec))),
    ]
    return [*readers, target]


def run(quick: bool = False) -> dict[str, Any]:
    """Twist and 640x480x3 Image one-way p50/p99, aiorobot's DDS transport and the bare pair, two processes."""
    from .. import run as aiorun
    from ._noise import NoiseMeter

    try:
        import cyclonedds  # noqa: F401
    except ImportError:
        return {"error": "cyclonedds is not installed (pip install cyclonedds)"}
    with NoiseMeter() as meter:
        domain_id = _domain()
        with subprocess.Popen(
            [sys.executable, "-c", _CHILD, str(domain_id)], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True
        ) as child:
            try:
                assert child.stdout is not None
                if child.stdout.readline().strip() != "ready":
                    figures: dict[str, Any] = {"error": "the subscriber process did not start"}
                else:
                    figures = aiorun(_measure(child, quick, domain_id))
            finally:
                child.kill()
    return {**figures, "noise": meter.result.as_dict()}


async def _measure(child: subprocess.Popen[str], quick: bool, domain_id: int) -> dict[str, Any]:
    import numpy as np
    from cyclonedds._clayer import ddspy_write
    from cyclonedds.pub import DataWriter
    from cyclonedds.topic import Topic

    from .. import HistoryPolicy, Node, QoSProfile
    from ..msgs.geometry_msgs import Twist, Vector3
    from ..msgs.sensor_msgs import Image

    n_lat, n_img, n_typed = (100, 10, 3) if quick else (1000, 200, 20)
    keep_all = QoSProfile(history=HistoryPolicy.KEEP_ALL)
    start = time.monotonic()  # discovery: from before this process's participant exists
    async with runtime(domain_id) as rt:
        node = rt.add_node(Node("bench_source"))
        twist = node.create_publisher(Twist, "/bench/twist", keep_all)
        image = node.create_publisher(Image, "/bench/image", keep_all)
        twist_t, image_t = _types()
        dp = rt.transport._participant
        bare_twist = DataWriter(dp, Topic(dp, "bench_bare_twist", twist_t), _qos())
        bare_image = DataWriter(dp, Topic(dp, "bench_bare_image", image_t), _qos())
        typed_twist = DataWriter(dp, Topic(dp, "bench_typed_twist", twist_t), _qos())
        typed_image = DataWriter(dp, Topic(dp, "bench_typed_image", image_t), _qos())
        discovered = None
        deadline = start + 20
        while time.monotonic() < deadline and not (
            twist.get_subscription_count() and image.get_subscription_count()
            and all(w.get_matched_subscriptions() for w in (bare_twist, bare_image, typed_twist, typed_image))
        ):
            if discovered is None and twist.get_subscription_count():
                discovered = time.monotonic() - start
            await asyncio.sleep(0.005)
        discovered = discovered if discovered is not None else time.monotonic() - start
        twist_cdr = bytearray(twist_t(linear=_vector(twist_t), angular=_vector(twist_t)).serialize())
        for _ in range(50):  # warm-up
            twist.publish(Twist(linear=Vector3(x=float(time.monotonic_ns()))))
            await asyncio.sleep(0.001)
        await _report(child)
        for _ in range(n_lat):
            twist.publish(Twist(linear=Vector3(x=float(time.monotonic_ns()))))
            await asyncio.sleep(0.001)  # latency, not throughput: the receiver is never behind
            struct.pack_into("<d", twist_cdr, 4, float(time.monotonic_ns()))
            ddspy_write(bare_twist._ref, bytes(twist_cdr))
            await asyncio.sleep(0.001)
            typed_twist.write(twist_t(linear=_vector(twist_t, float(time.monotonic_ns())), angular=_vector(twist_t)))
            await asyncio.sleep(0.001)
        await _send_images(image, n_img)
        data = np.zeros(640 * 480 * 3, dtype=np.uint8)
        image_cdr = bytearray(_bare_image(image_t, data))
        for _ in range(n_img):
            struct.pack_into("<iI", image_cdr, 4, *divmod(time.monotonic_ns(), 1_000_000_000))
            ddspy_write(bare_image._ref, bytes(image_cdr))
            await asyncio.sleep(0.01)
        typed = _bare_image(image_t, data, typed=True)
        for _ in range(n_typed):  # a list of 921,600 ints each way: slow, so fewer
            typed.header.stamp.sec, typed.header.stamp.nanosec = divmod(time.monotonic_ns(), 1_000_000_000)
            typed_image.write(typed)
            await asyncio.sleep(0.1 if quick else 0.2)
        await asyncio.sleep(0.3)
        lat = (await _report(child))["lat"]
    return {
        "discovery_sec": discovered,
        "twist": _stats(lat["twist"]), "bare_twist": _stats(lat["bare_twist"]),
        "image": _stats(lat["image"]), "bare_image": _stats(lat["bare_image"]),
        "typed_twist": _stats(lat["typed_twist"]), "typed_image": _stats(lat["typed_image"]),
    }


def _vector(twist_t: Any, x: float = 0.0) -> Any:
    """A ``Vector3_`` of the Twist struct (linear.x carries the stamp)."""
    import typing

    return typing.get_type_hints(twist_t)["linear"](x=x, y=0.0, z=0.0)


def _bare_image(image_t: Any, data: Any, *, typed: bool = False) -> Any:
    """A 640x480 rgb8 Image's CDR made by cyclonedds-python itself (stamp at bytes 4..12, patched per
    send), or with ``typed`` the ``IdlStruct`` sample (its data a list, as the binding reads it back)."""
    import typing

    hints = typing.get_type_hints(image_t)
    header_t = hints["header"]
    stamp_t = typing.get_type_hints(header_t)["stamp"]
    msg = image_t(header=header_t(stamp=stamp_t(sec=0, nanosec=0), frame_id=""), height=480, width=640,
                  encoding="rgb8", is_bigendian=0, step=640 * 3, data=data.tolist() if typed else data.tobytes())
    return msg if typed else bytes(msg.serialize())


def table(part: dict[str, Any]) -> Any:
    from ._report import figure_table

    title = "DDS transport vs bare cyclonedds-python (two processes, loopback)"
    if "error" in part:
        return figure_table(title, ("path", "note"), [("dds", part["error"])])
    nan = float("nan")

    def row(name: str, key: str) -> tuple[str, float, float, float, float, float]:
        ours, bare, typed = part[key], part["bare_" + key], part["typed_" + key]
        p50 = [d.get("p50_us", nan) if d.get("n") else nan for d in (ours, bare, typed)]
        return (name, p50[0], p50[1], p50[0] / p50[1], p50[2], p50[0] / p50[2])

    return figure_table(
        title,
        ("message", "aiorobot p50 us", "bare bytes p50 us", "ratio", "bare IdlStruct p50 us", "ratio"),
        [row("Twist one-way", "twist"), row("Image 640x480x3 one-way", "image")],
        caption=f"a new process saw the other's topic {part['discovery_sec']:.2f} s after it started opening its participant",
    )
