"""Writes a rosbag2 directory: MCAP storage (``ros2`` profile, ``ros2msg`` schemas, CDR) + metadata.yaml.

Messages go to the file chunk by chunk (``mcap``'s writer appends each finished chunk), so a
recorder killed mid-run leaves every completed chunk readable; ``aiorobot bag reindex`` then
rebuilds the summary and ``metadata.yaml``. Splitting follows ``ros2 bag record``'s
``--max-bag-size`` / ``--max-bag-duration``: a new ``<name>_<i>.mcap`` file each time a limit is hit.
"""

from __future__ import annotations

from pathlib import Path
from typing import IO, Any

from .._core._qos import QoSProfile
from ._metadata import BagError, TopicInfo, qos_yaml, write_metadata

__all__ = ["BagWriter"]

#: Chunk size of the MCAP files: what a crash can lose at most, per file.
CHUNK_SIZE = 256 * 1024


class BagWriter:
    """A rosbag2 (MCAP) bag being written. Not thread-safe: one writer thread at a time.

    ``add_topic(name, type_name, qos)`` before the topic's first ``write(name, time_ns, cdr)``;
    ``close()`` finishes the file and writes ``metadata.yaml``. Use as a context manager.
    ``compression`` is the MCAP chunk compression: ``"none"`` (rosbag2's default), ``"zstd"``
    or ``"lz4"`` (``ros2 bag record --storage-preset-profile zstd_fast`` gives zstd chunks too).
    """

    def __init__(
        self,
        directory: str | Path,
        *,
        max_bag_size: int = 0,
        max_bag_duration_ns: int = 0,
        chunk_size: int = CHUNK_SIZE,
        compression: str = "none",
    ) -> None:
        self.directory = Path(directory)
        if self.directory.exists():
            raise BagError(f"{self.directory}: exists already; choose another output directory (-o) or remove it")
        try:
            self.directory.mkdir(parents=True)
        except OSError as err:
            raise BagError(f"{self.directory}: cannot create the bag directory ({err.strerror})") from None
        self.max_bag_size = max_bag_size
        self.max_bag_duration_ns = max_bag_duration_ns
        self.chunk_size = chunk_size
        if compression not in ("none", "zstd", "lz4"):
            raise BagError(f"compression: expected 'none', 'zstd' or 'lz4', found {compression!r}")
        self.compression = compression
        self.topics: dict[str, TopicInfo] = {}
        self._files: list[dict[str, Any]] = []
        self._stream: IO[bytes] | None = None
        self._mcap: Any = None
        self._channels: dict[str, int] = {}
        self._schemas: dict[str, int] = {}
        self._sequence: dict[str, int] = {}
        self.closed = False
        self._open_file()

    def __repr__(self) -> str:
        return f"<BagWriter {self.directory} topics={len(self.topics)} messages={self.message_count}>"

    def __enter__(self) -> BagWriter:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    @property
    def message_count(self) -> int:
        return sum(t.message_count for t in self.topics.values())

    @property
    def files(self) -> list[Path]:
        return [self.directory / f["path"] for f in self._files]

    # -- topics and messages ------------------------------------------------------------

    def add_topic(self, name: str, type_name: str, qos: QoSProfile | None = None) -> None:
        """Declare ``name`` with its ROS type name (``"geometry_msgs/msg/Twist"``) and offered QoS."""
        from aiorobot.msgs import type_hash

        if name in self.topics:
            if self.topics[name].type != type_name:
                raise BagError(
                    f"{self.directory}: topic {name} is recorded as {self.topics[name].type}; "
                    f"a second type {type_name} on the same topic cannot be recorded"
                )
            return
        self.topics[name] = TopicInfo(name, type_name, type_hash(type_name), qos or QoSProfile())
        self._sequence[name] = 0
        self._register(name)

    def write(self, topic: str, time_ns: int, data: bytes) -> None:
        """Append one CDR-serialised message of ``topic`` received at ``time_ns``."""
        info = self.topics.get(topic)
        if info is None:
            raise BagError(f"{self.directory}: write to {topic} before add_topic({topic!r}, ...)")
        current = self._files[-1]
        if self._must_split(current, time_ns):
            self._split()
            current = self._files[-1]
        self._sequence[topic] += 1
        self._mcap.add_message(self._channels[topic], log_time=time_ns, data=data, publish_time=time_ns, sequence=self._sequence[topic])
        info.message_count += 1
        if current["message_count"] == 0:
            current["start_ns"] = time_ns
        current["start_ns"] = min(current["start_ns"], time_ns)
        current["end_ns"] = max(current.get("end_ns", time_ns), time_ns)
        current["duration_ns"] = current["end_ns"] - current["start_ns"]
        current["message_count"] += 1
        current["bytes"] += len(data)

    def split(self) -> None:
        """Close the current file and go on in a new one (rosbag2's ``split_bagfile``)."""
        if self.closed:
            raise BagError(f"{self.directory}: split after close")
        self._split()

    def checkpoint(self) -> None:
        """Finish the current file and write ``metadata.yaml`` for the files finished so far, so the
        directory reads as a complete bag while writing goes on in a new file (a snapshot's end)."""
        if self.closed:
            raise BagError(f"{self.directory}: checkpoint after close")
        self._split()
        write_metadata(self.directory, self._files[:-1], list(self.topics.values()))

    def close(self) -> None:
        """Finish the MCAP file (summary, footer) and write ``metadata.yaml``. Idempotent.

        A last file that received nothing after a split or checkpoint is removed rather than listed.
        """
        if self.closed:
            return
        self.closed = True
        self._close_file()
        if len(self._files) > 1 and self._files[-1]["message_count"] == 0:
            (self.directory / self._files.pop()["path"]).unlink()
        write_metadata(self.directory, self._files, list(self.topics.values()))

    # -- files ------------------------------------------------------------------------

    def _must_split(self, current: dict[str, Any], time_ns: int) -> bool:
        if current["message_count"] == 0:
            return False
        if self.max_bag_size and current["bytes"] >= self.max_bag_size:
            return True
        return bool(self.max_bag_duration_ns and time_ns - current["start_ns"] >= self.max_bag_duration_ns)

    def _open_file(self) -> None:
        from mcap.writer import CompressionType, Writer

        name = f"{self.directory.name}_{len(self._files)}.mcap"
        self._stream = open(self.directory / name, "wb")  # noqa: SIM115 - closed in _close_file
        kind = {"none": CompressionType.NONE, "zstd": CompressionType.ZSTD, "lz4": CompressionType.LZ4}[self.compression]
        self._mcap = Writer(self._stream, chunk_size=self.chunk_size, compression=kind)
        self._mcap.start(profile="ros2", library="aiorobot")
        self._files.append({"path": name, "start_ns": 0, "duration_ns": 0, "message_count": 0, "bytes": 0})
        self._channels.clear()
        self._schemas.clear()
        for topic in self.topics:
            self._register(topic)

    def _register(self, topic: str) -> None:
        from aiorobot.msgs import message_definition

        info = self.topics[topic]
        schema = self._schemas.get(info.type)
        if schema is None:
            schema = self._mcap.register_schema(info.type, "ros2msg", message_definition(info.type).encode())
            self._schemas[info.type] = schema
        self._channels[topic] = self._mcap.register_channel(
            topic, "cdr", schema, metadata={"offered_qos_profiles": qos_yaml(info.qos)}
        )

    def _close_file(self) -> None:
        if self._mcap is not None:
            self._mcap.finish()
            self._mcap = None
        if self._stream is not None:
            self._stream.close()
            self._stream = None

    def _split(self) -> None:
        self._close_file()
        self._open_file()
