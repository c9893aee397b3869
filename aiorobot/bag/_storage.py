"""The storage files of a bag being written: MCAP (rosbag2's default) and SQLite3 (``.db3``).

Both take the same calls from :class:`BagWriter`: ``register(topic, info)`` once per topic and
file, ``write(topic, time_ns, data, sequence)``, ``close(metadata_text)``.

- MCAP: ``ros2`` profile, ``ros2msg`` schemas, CDR; chunk compression ``none``/``zstd``/``lz4``
  (what ``ros2 bag record --storage-preset-profile zstd_fast`` writes). ``mcap``'s writer
  appends each finished chunk, so a killed recorder leaves every completed chunk readable.
- SQLite3: rosbag2_storage_sqlite3's schema version 4 as ROS 2 Jazzy writes it (``schema``,
  ``metadata``, ``topics`` with QoS YAML and type hash, ``message_definitions``, ``messages``
  with a timestamp index); each file's ``metadata`` table gets the bag's ``metadata.yaml`` as it
  stood when the file was closed, as rosbag2 does. SQLite3 has no chunk compression.
"""

from __future__ import annotations

from pathlib import Path
from typing import IO, Any

from ._metadata import BagError, TopicInfo, qos_yaml

__all__ = ["COMPRESSIONS", "STORAGES", "McapFile", "Sqlite3File", "open_storage_file"]

#: storage identifier -> file suffix
STORAGES = {"mcap": ".mcap", "sqlite3": ".db3"}
#: MCAP chunk compressions
COMPRESSIONS = ("none", "zstd", "lz4")


def _qos_text(info: TopicInfo) -> str:
    return info.qos_text or qos_yaml(info.qos)


class McapFile:
    """One ``.mcap`` storage file."""

    def __init__(self, path: Path, *, chunk_size: int, compression: str) -> None:
        from mcap.writer import CompressionType, Writer

        self.path = path
        self._stream: IO[bytes] | None = open(path, "wb")  # noqa: SIM115 - closed in close()
        kind = {"none": CompressionType.NONE, "zstd": CompressionType.ZSTD, "lz4": CompressionType.LZ4}[compression]
        self._mcap: Any = Writer(self._stream, chunk_size=chunk_size, compression=kind)
        self._mcap.start(profile="ros2", library="aiorobot")
        self._channels: dict[str, int] = {}
        self._schemas: dict[str, int] = {}

    def register(self, topic: str, info: TopicInfo, definition: str) -> None:
        schema = self._schemas.get(info.type)
        if schema is None:
            schema = self._mcap.register_schema(info.type, "ros2msg", definition.encode())
            self._schemas[info.type] = schema
        self._channels[topic] = self._mcap.register_channel(topic, "cdr", schema, metadata={"offered_qos_profiles": _qos_text(info)})

    def write(self, topic: str, time_ns: int, data: bytes, sequence: int) -> None:
        self._mcap.add_message(self._channels[topic], log_time=time_ns, data=data, publish_time=time_ns, sequence=sequence)

    def close(self, metadata_text: str) -> None:
        if self._mcap is not None:
            self._mcap.finish()
            self._mcap = None
        if self._stream is not None:
            self._stream.close()
            self._stream = None


_SQLITE_SCHEMA = """
CREATE TABLE schema(schema_version INTEGER PRIMARY KEY, ros_distro TEXT NOT NULL);
CREATE TABLE metadata(id INTEGER PRIMARY KEY, metadata_version INTEGER NOT NULL, metadata TEXT NOT NULL);
CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL, serialization_format TEXT NOT NULL,
                    offered_qos_profiles TEXT NOT NULL, type_description_hash TEXT NOT NULL);
CREATE TABLE message_definitions(id INTEGER PRIMARY KEY, topic_type TEXT NOT NULL, encoding TEXT NOT NULL,
                                 encoded_message_definition TEXT NOT NULL, type_description_hash TEXT NOT NULL);
CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, timestamp INTEGER NOT NULL, data BLOB NOT NULL);
CREATE INDEX timestamp_idx ON messages (timestamp ASC);
INSERT INTO schema(schema_version, ros_distro) VALUES (4, 'jazzy');
"""


class Sqlite3File:
    """One ``.db3`` storage file (committed every ``commit_every`` messages and at close)."""

    def __init__(self, path: Path, *, commit_every: int = 1000) -> None:
        import sqlite3

        self.path = path
        # opened where the writer is built, written by its writer thread: one thread at a time, as BagWriter says
        self._conn = sqlite3.connect(str(path), check_same_thread=False)
        self._conn.executescript(_SQLITE_SCHEMA)
        self._ids: dict[str, int] = {}
        self._types: set[str] = set()
        self._pending = 0
        self._commit_every = commit_every

    def register(self, topic: str, info: TopicInfo, definition: str) -> None:
        if info.type not in self._types:
            self._types.add(info.type)
            self._conn.execute(
                "INSERT INTO message_definitions (topic_type, encoding, encoded_message_definition, type_description_hash) "
                "VALUES (?, ?, ?, ?)",
                (info.type, "ros2msg", definition, info.type_hash),
            )
        cur = self._conn.execute(
            "INSERT INTO topics (name, type, serialization_format, offered_qos_profiles, type_description_hash) VALUES (?, ?, ?, ?, ?)",
            (topic, info.type, "cdr", _qos_text(info), info.type_hash),
        )
        self._ids[topic] = int(cur.lastrowid or 0)

    def write(self, topic: str, time_ns: int, data: bytes, sequence: int) -> None:
        self._conn.execute("INSERT INTO messages (topic_id, timestamp, data) VALUES (?, ?, ?)", (self._ids[topic], time_ns, data))
        self._pending += 1
        if self._pending >= self._commit_every:
            self._conn.commit()
            self._pending = 0

    def close(self, metadata_text: str) -> None:
        from ._metadata import VERSION

        if self._conn is None:
            return
        self._conn.execute("INSERT INTO metadata (metadata_version, metadata) VALUES (?, ?)", (VERSION, metadata_text))
        self._conn.commit()
        self._conn.close()
        self._conn = None  # type: ignore[assignment]


def open_storage_file(directory: Path, index: int, storage: str, *, chunk_size: int, compression: str) -> McapFile | Sqlite3File:
    """The ``index``-th storage file of the bag in ``directory`` (``<name>_<index>.mcap`` or ``.db3``)."""
    if storage not in STORAGES:
        raise BagError(f"storage: expected 'mcap' or 'sqlite3', found {storage!r}")
    path = directory / f"{directory.name}_{index}{STORAGES[storage]}"
    if storage == "sqlite3":
        return Sqlite3File(path)
    return McapFile(path, chunk_size=chunk_size, compression=compression)
