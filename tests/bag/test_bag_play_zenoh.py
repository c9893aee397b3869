"""``aiorobot bag play`` over zenoh of a type only the bag defines: another process learns it.

The player registers the type from the bag's definition and answers ``~/get_type_description``
(as every ROS 2 Jazzy node does); the receiving process, which never heard of the type, asks for
it when the publisher appears, so the topic is in its graph and its messages decode.
"""

from __future__ import annotations

import asyncio
import sys
from pathlib import Path
from typing import Any

from aiorobot import Node, QoSProfile, ReliabilityPolicy
from aiorobot.msgs import get
from tests.transport._helpers import free_port, open_router, peer_env, peer_runtime, wait_until

from ._ros2_bags import BagTopic, ros2_bag

READING = "string label\nbagzenoh_msgs/Point3 where\nfloat64[] values\n"
POINT3 = "float64 x\nfloat64 y\nfloat64 z\n"


def _bag(tmp_path: Path) -> Path:
    import numpy as np
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    store = get_typestore(Stores.ROS2_JAZZY)
    store.register(get_types_from_msg(POINT3, "bagzenoh_msgs/msg/Point3"))
    store.register(get_types_from_msg(READING, "bagzenoh_msgs/msg/Reading"))
    Reading, Point3 = store.types["bagzenoh_msgs/msg/Reading"], store.types["bagzenoh_msgs/msg/Point3"]
    definition = READING + "=" * 80 + "\nMSG: bagzenoh_msgs/Point3\n" + POINT3
    messages = [
        (1_000_000_000 + i * 50_000_000,
         bytes(store.serialize_cdr(Reading(label=f"r{i}", where=Point3(x=float(i), y=2.0, z=3.0), values=np.array([0.5, float(i)])),
                                   "bagzenoh_msgs/msg/Reading")))
        for i in range(3)
    ]
    return ros2_bag(tmp_path / "readings", "mcap", [BagTopic("/readings", "bagzenoh_msgs/msg/Reading", definition, messages)]).path


async def test_a_type_only_the_bag_defines_reaches_another_process_over_zenoh(tmp_path: Path) -> None:
    bag = _bag(tmp_path)
    port = free_port()
    router = open_router(port)
    env = peer_env(tmp_path, port)
    player = await asyncio.create_subprocess_exec(sys.executable, "-m", "aiorobot.cli", "bag", "play", str(bag), "--loop",
                                                  env=env, stdout=asyncio.subprocess.DEVNULL, stderr=asyncio.subprocess.DEVNULL)
    got: list[Any] = []
    try:
        async with peer_runtime(port) as rt:
            def listed() -> bool:
                return any(t.name == "/readings" for t in rt.graph.topics)

            await wait_until(listed, 20)  # not listed at all before: the type was unknown here
            topic = next(t for t in rt.graph.topics if t.name == "/readings")
            assert list(topic.types) == ["bagzenoh_msgs/msg/Reading"]
            arrived = asyncio.Event()

            def on_msg(m: Any) -> None:
                got.append(m)
                arrived.set()

            node = rt.add_node(Node("probe"))
            node.create_subscription(get("bagzenoh_msgs/msg/Reading"), "/readings", on_msg,
                                     QoSProfile(reliability=ReliabilityPolicy.BEST_EFFORT, depth=10))
            await asyncio.wait_for(arrived.wait(), 40)
    finally:
        player.terminate()
        await player.wait()
        router.close()
    m = got[0]
    i = int(m.label[1:])
    assert (m.where.x, m.where.y, m.where.z) == (float(i), 2.0, 3.0)
    assert list(m.values) == [0.5, float(i)]


def test_a_type_description_registers_what_it_describes_with_the_same_hash() -> None:
    """What ``~/get_type_description`` answers is enough to rebuild a type: same fields, same RIHS01."""
    import copy

    from aiorobot.msgs import register_type_description, type_description, type_hash

    for name in ("sensor_msgs/msg/Imu", "example_interfaces/srv/AddTwoInts_Event", "std_msgs/msg/Empty", "nav_msgs/msg/OccupancyGrid"):
        described = copy.deepcopy(type_description(name))
        package = name.split("/")[0] + "/"

        def renamed(type_name: str) -> str:  # the package's own types, as if nobody here knew them
            return "bagdesc_" + type_name if type_name.startswith(package) else type_name

        for part in (described.type_description, *described.referenced_type_descriptions):
            part.type_name = renamed(part.type_name)
            for f in part.fields:
                f.type.nested_type_name = renamed(f.type.nested_type_name)
        described.referenced_type_descriptions.sort(key=lambda d: d.type_name)
        cls = register_type_description(described)
        assert cls.__msgtype__ == "bagdesc_" + name
        assert type_description(cls) == described  # hence the same hash as the describing side computes
        assert type_hash(cls) != type_hash(name)  # the names are part of the hash
