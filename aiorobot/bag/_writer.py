"""Writes a rosbag2 directory: MCAP (``ros2`` profile, ``ros2msg`` schemas, CDR) or SQLite3 storage + metadata.yaml.

Messages go to the file chunk by chunk (``mcap``'s writer appends each finished chunk), so a
recorder killed mid-run leaves every completed chunk readable; ``aiorobot bag reindex`` then
rebuilds the summary and ``metadata.yaml``. Splitting follows ``ros2 bag record``'s
``--max-bag-size`` / ``--max-bag-duration``: a new ``<name>_<i>.mcap`` file each time a limit is hit.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from .._core._qos import QoSProfile
from ._metadata import BagError, TopicInfo, metadata_text, write_metadata
from ._storage import COMPRESSIONS, STORAGES, McapFile, Sqlite3File, open_storage_file

__all__ = ["BagWriter"]

#: Chunk size of the MCAP files: what a crash can lose at most, per file.
CHUNK_SIZE = 256 * 1024


class BagWriter:
    """A rosbag2 bag being written. Not thread-safe: one writer thread at a time.

    ``add_topic(name, type_name, qos)`` before the topic's first ``write(name, time_ns, cdr)``;
    ``close()`` finishes the file and writes ``metadata.yaml``. Use as a context manager.
    ``compression`` is the MCAP chunk compression: ``"none"`` (rosbag2's default), ``"zstd"``
    or ``"lz4"`` (``ros2 bag record --storage-preset-profile zstd_fast`` gives zstd chunks too).
    ``storage`` is ``"mcap"`` (rosbag2's default) or ``"sqlite3"`` (``.db3``, no compression).
    ``compression_mode`` is rosbag2's own zstd compression instead: ``"file"`` (each finished
    storage file becomes ``<file>.zstd``) or ``"message"`` (each message's bytes), either storage.
    """

    def __init__(
        self,
        directory: str | Path,
        *,
        max_bag_size: int = 0,
        max_bag_duration_ns: int = 0,
        chunk_size: int = CHUNK_SIZE,
        compression: str = "none",
        storage: str = "mcap",
        compression_mode: str = "",
    ) -> None:
        self.directory = Path(directory)
        if storage not in STORAGES:
            raise BagError(f"storage: expected 'mcap' or 'sqlite3', found {storage!r}")
        if compression not in COMPRESSIONS:
            raise BagError(f"compression: expected 'none', 'zstd' or 'lz4', found {compression!r}")
        if compression_mode not in ("", "file", "message"):
            raise BagError(f"compression_mode: expected '', 'file' or 'message' (zstd, as rosbag2), found {compression_mode!r}")
        if compression_mode and compression != "none":
            raise BagError(f"compression_mode {compression_mode!r} compresses with zstd already; leave the MCAP chunks uncompressed")
        if storage == "sqlite3" and compression != "none":
            raise BagError(f"compression {compression!r} is MCAP chunk compression; sqlite3 storage is written uncompressed")
        if self.directory.exists():
            raise BagError(f"{self.directory}: exists already; choose another output directory (-o) or remove it")
        try:
            self.directory.mkdir(parents=True)
        except OSError as err:
            raise BagError(f"{self.directory}: cannot create the bag directory ({err.strerror})") from None
        self.max_bag_size = max_bag_size
        self.max_bag_duration_ns = max_bag_duration_ns
        self.chunk_size = chunk_size
        self.compression = compression
        self.storage = storage
        self.compression_mode = compression_mode
        self._deflate: Any = None
        if compression_mode == "message":
            from ._reader import _zstd

            self._deflate = _zstd().compress
        self.topics: dict[str, TopicInfo] = {}
        self._files: list[dict[str, Any]] = []
        self._file: McapFile | Sqlite3File | None = None
        self._definitions: dict[str, str] = {}
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

    def add_topic(self, name: str, type_name: str, qos: QoSProfile | None = None, *, qos_text: str = "") -> None:
        """Declare ``name`` with its ROS type name (``"geometry_msgs/msg/Twist"``) and offered QoS.

        ``qos_text``: the offered QoS profiles as YAML, kept verbatim (a bag being converted).
        """
        from aiorobot.msgs import type_hash

        if name in self.topics:
            if self.topics[name].type != type_name:
                raise BagError(
                    f"{self.directory}: topic {name} is recorded as {self.topics[name].type}; "
                    f"a second type {type_name} on the same topic cannot be recorded"
                )
            return
        self.topics[name] = TopicInfo(name, type_name, type_hash(type_name), qos or QoSProfile(), qos_text=qos_text)
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
        if self._deflate is not None:
            data = self._deflate(data)
        assert self._file is not None
        self._file.write(topic, time_ns, data, self._sequence[topic])
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
        write_metadata(self.directory, self._files[:-1], list(self.topics.values()), **self._metadata_options())

    def close(self) -> None:
        """Finish the MCAP file (summary, footer) and write ``metadata.yaml``. Idempotent.

        A last file that received nothing after a split or checkpoint is removed rather than listed.
        """
        if self.closed:
            return
        self.closed = True
        self._close_file(compress=False)
        if len(self._files) > 1 and self._files[-1]["message_count"] == 0:
            (self.directory / self._files.pop()["path"]).unlink()
        else:
            self._compress_file()
        write_metadata(self.directory, self._files, list(self.topics.values()), **self._metadata_options())

    # -- files ------------------------------------------------------------------------

    def _must_split(self, current: dict[str, Any], time_ns: int) -> bool:
        if current["message_count"] == 0:
            return False
        if self.max_bag_size and current["bytes"] >= self.max_bag_size:
            return True
        return bool(self.max_bag_duration_ns and time_ns - current["start_ns"] >= self.max_bag_duration_ns)

    def _open_file(self) -> None:
        self._file = open_storage_file(
            self.directory, len(self._files), self.storage, chunk_size=self.chunk_size, compression=self.compression
        )
        self._files.append({"path": self._file.path.name, "start_ns": 0, "duration_ns": 0, "message_count": 0, "bytes": 0})
        for topic in self.topics:
            self._register(topic)

    def _register(self, topic: str) -> None:
        from aiorobot.msgs import message_definition

        info = self.topics[topic]
        if info.type not in self._definitions:
            self._definitions[info.type] = message_definition(info.type)
        assert self._file is not None
        self._file.register(topic, info, self._definitions[info.type])

    def _metadata_options(self) -> dict[str, str]:
        return {"storage": self.storage, "compression_mode": self.compression_mode.upper()}

    def _close_file(self, *, compress: bool = True) -> None:
        if self._file is not None:
            self._file.close(metadata_text(self._files, list(self.topics.values()), **self._metadata_options()))
            self._file = None
            if compress:
                self._compress_file()

    def _compress_file(self) -> None:
        """With ``compression_mode="file"``: the last (closed) storage file -> ``<file>.zstd``, as rosbag2."""
        if self.compression_mode != "file":
            return
        import shutil

        from ._reader import _zstd

        entry = self._files[-1]
        plain = self.directory / entry["path"]
        with plain.open("rb") as src, _zstd().open(plain.with_name(plain.name + ".zstd"), "wb") as dst:
            shutil.copyfileobj(src, dst)
        plain.unlink()
        entry["path"] = plain.name + ".zstd"

    def _split(self) -> None:
        self._close_file()
        self._open_file()
