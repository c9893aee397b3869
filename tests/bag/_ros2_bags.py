"""Bags built the way ``ros2 bag record`` (Jazzy) writes them, for tests that must not depend on aiorobot's writer.

The storage is written with the ``mcap`` package (MCAP) or ``sqlite3`` (rosbag2's schema version 4
tables), the CDR with rosbags' typestore, and ``metadata.yaml`` as literal YAML text in rosbag2's
version 9 shape. As in bags ros2 records, the QoS in ``metadata.yaml`` and in the storage are
written differently (``deadline: {sec: 0, nsec: 0}`` against ``2147483647 / 4294967295``). The
content restates what ros2/rosbag2's test bags hold (``talker``, ``bag_with_topics_and_service_events``,
``test_bag_for_seek``, ``convert_a``): a plain topic, a service-event topic, an old-style type name
and a type with an empty definition.
"""

from __future__ import annotations

import sqlite3
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

__all__ = ["BagTopic", "Ros2Bag", "qos_text", "ros2_bag", "stored_counts", "typestore", "write_mcap"]


def qos_text(deadline_sec: int, deadline_nsec: int, *, indent: str = "") -> str:
    """One offered QoS profile as rosbag2 Jazzy dumps it (YAML sequence of one mapping)."""
    lines = [
        "- history: keep_last",
        "  depth: 10",
        "  reliability: reliable",
        "  durability: volatile",
        "  deadline:",
        f"    sec: {deadline_sec}",
        f"    nsec: {deadline_nsec}",
        "  lifespan:",
        "    sec: 9223372036",
        "    nsec: 854775807",
        "  liveliness: automatic",
        "  liveliness_lease_duration:",
        f"    sec: {deadline_sec}",
        f"    nsec: {deadline_nsec}",
        "  avoid_ros_namespace_conventions: false",
    ]
    return "\n".join(indent + line for line in lines)


#: What the storage holds (the profile the publisher offered, as DDS reports it) ...
STORAGE_QOS = qos_text(2147483647, 4294967295)
#: ... and what metadata.yaml says for the same topic.
METADATA_QOS_ARGS = (0, 0)


@dataclass
class BagTopic:
    name: str
    type: str  # as the bag names it (maybe old-style "pkg/Type")
    definition: str | None  # the ros2msg text the storage keeps; None: none stored
    messages: list[tuple[int, bytes]] = field(default_factory=list)
    metadata_count: int | None = None  # what metadata.yaml claims; None: the true count


@dataclass
class Ros2Bag:
    path: Path
    topics: list[BagTopic]
    starting_time: int  # metadata.yaml's starting_time (may be later than the first message)


def ros2_bag(path: Path, storage: str, topics: list[BagTopic], *, starting_time: int | None = None,
             metadata_only: list[tuple[str, str, int]] = (),  # type: ignore[assignment]
             statistics_start: int | None = None) -> Ros2Bag:
    """Write the bag directory ``path`` (``storage``: ``"mcap"`` or ``"sqlite3"``) and its metadata.yaml.

    ``metadata_only``: ``(name, type, count)`` topics metadata.yaml lists that the storage lacks.
    ``statistics_start``: the MCAP statistics' message_start_time, when it should not be the true
    one (libmcap, which rosbag2 uses, leaves a message stamped 0 out of it: rosbag2's convert_a).
    """
    path.mkdir(parents=True)
    file = path / f"{path.name}_0.{'mcap' if storage == 'mcap' else 'db3'}"
    if storage == "mcap":
        write_mcap(file, topics, statistics_start)
    else:
        _write_db3(file, topics)
    times = [t for topic in topics for t, _ in topic.messages]
    first, last = min(times), max(times)
    start = first if starting_time is None else starting_time
    entries = [(t.name, t.type, t.metadata_count if t.metadata_count is not None else len(t.messages)) for t in topics]
    entries += list(metadata_only)
    yaml = [
        "rosbag2_bagfile_information:",
        "  version: 9",
        f"  storage_identifier: {storage}",
        "  duration:",
        f"    nanoseconds: {last - start}",
        "  starting_time:",
        f"    nanoseconds_since_epoch: {start}",
        f"  message_count: {sum(n for _, _, n in entries)}",
        "  topics_with_message_count:",
    ]
    for name, type_name, count in entries:
        yaml += [
            "    - topic_metadata:",
            f"        name: {name}",
            f"        type: {type_name}",
            "        serialization_format: cdr",
            "        offered_qos_profiles:",
            qos_text(*METADATA_QOS_ARGS, indent="          "),
            '        type_description_hash: ""',
            f"      message_count: {count}",
        ]
    yaml += [
        '  compression_format: ""',
        '  compression_mode: ""',
        "  relative_file_paths:",
        f"    - {file.name}",
        "  files:",
        f"    - path: {file.name}",
        "      starting_time:",
        f"        nanoseconds_since_epoch: {start}",
        "      duration:",
        f"        nanoseconds: {last - start}",
        f"      message_count: {sum(len(t.messages) for t in topics)}",
        "  custom_data: ~",
        "  ros_distro: jazzy",
        "",
    ]
    (path / "metadata.yaml").write_text("\n".join(yaml), encoding="utf8")
    return Ros2Bag(path, topics, start)


def write_mcap(file: Path, topics: list[BagTopic], statistics_start: int | None = None) -> None:
    from mcap.writer import Writer

    with open(file, "wb") as stream:
        writer = Writer(stream)
        writer.start(profile="ros2", library="libmcap 1.1.0")
        channels: dict[str, int] = {}
        for topic in topics:
            schema = 0 if topic.definition is None else writer.register_schema(topic.type, "ros2msg", topic.definition.encode())
            channels[topic.name] = writer.register_channel(
                topic.name, "cdr", schema, metadata={"offered_qos_profiles": STORAGE_QOS, "topic_type_hash": ""}
            )
        merged = sorted((t, topic.name, data) for topic in topics for t, data in topic.messages)
        for seq, (t, name, data) in enumerate(merged, 1):
            writer.add_message(channels[name], log_time=t, publish_time=t, data=data, sequence=seq)
        if statistics_start is not None:
            writer._Writer__statistics.message_start_time = statistics_start  # type: ignore[attr-defined]
        writer.finish()


def _write_db3(file: Path, topics: list[BagTopic]) -> None:
    """rosbag2_storage_sqlite3's schema version 4 (Iron, Jazzy): topics, message_definitions, messages."""
    db = sqlite3.connect(file)
    db.executescript(
        """
        CREATE TABLE schema(schema_version INTEGER PRIMARY KEY, ros_distro TEXT NOT NULL);
        CREATE TABLE metadata(id INTEGER PRIMARY KEY, metadata_version INTEGER NOT NULL, metadata TEXT NOT NULL);
        CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL,
            serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL, type_description_hash TEXT NOT NULL);
        CREATE TABLE message_definitions(id INTEGER PRIMARY KEY, topic_type TEXT NOT NULL, encoding TEXT NOT NULL,
            encoded_message_definition TEXT NOT NULL, type_description_hash TEXT NOT NULL);
        CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, timestamp INTEGER NOT NULL, data BLOB NOT NULL);
        CREATE INDEX timestamp_idx ON messages (timestamp ASC);
        INSERT INTO schema VALUES (4, 'jazzy');
        """
    )
    defined: set[str] = set()
    for i, topic in enumerate(topics, 1):
        db.execute("INSERT INTO topics VALUES (?, ?, ?, 'cdr', ?, '')", (i, topic.name, topic.type, STORAGE_QOS))
        if topic.definition is not None and topic.type not in defined:
            defined.add(topic.type)
            db.execute("INSERT INTO message_definitions (topic_type, encoding, encoded_message_definition, type_description_hash) "
                       "VALUES (?, 'ros2msg', ?, '')", (topic.type, topic.definition))
        db.executemany("INSERT INTO messages (topic_id, timestamp, data) VALUES (?, ?, ?)",
                       [(i, t, data) for t, data in topic.messages])
    db.commit()
    db.close()


def stored_counts(bag: Ros2Bag) -> dict[str, int]:
    """Messages per topic, read straight from the storage file with ``mcap`` or ``sqlite3`` (not through aiorobot)."""
    file = next(p for p in bag.path.iterdir() if p.suffix in (".mcap", ".db3"))
    counts: dict[str, int] = {}
    if file.suffix == ".mcap":
        from mcap.reader import make_reader

        with open(file, "rb") as stream:
            for _, channel, _ in make_reader(stream).iter_messages():
                counts[channel.topic] = counts.get(channel.topic, 0) + 1
        return counts
    db = sqlite3.connect(file)
    try:
        for name, n in db.execute("SELECT t.name, count(*) FROM messages m JOIN topics t ON m.topic_id = t.id GROUP BY t.name"):
            counts[name] = n
    finally:
        db.close()
    return counts


def typestore(pkg: str) -> Any:
    """A rosbags typestore (Jazzy) with the test types of package prefix ``pkg`` (layouts as in the bag)."""
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    store = get_typestore(Stores.ROS2_JAZZY)
    store.register(get_types_from_msg("int64 a\nint64 b\n", f"{pkg}_srvs/msg/AddRequest"))
    store.register(get_types_from_msg("int64 sum\n", f"{pkg}_srvs/msg/AddResponse"))
    store.register(get_types_from_msg(
        f"service_msgs/ServiceEventInfo info\n{pkg}_srvs/AddRequest[<=1] request\n{pkg}_srvs/AddResponse[<=1] response\n",
        f"{pkg}_srvs/msg/AddEvent"))
    store.register(get_types_from_msg("float64 x\nfloat64 y\n", f"{pkg}_old/msg/Point2"))
    store.register(get_types_from_msg("uint8 structure_needs_at_least_one_member\n", f"{pkg}_empty/msg/Nothing"))
    return store
