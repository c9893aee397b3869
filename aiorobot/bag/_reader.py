"""Reads rosbag2 directories (MCAP or SQLite3 storage) as rosbag2 itself does.

``metadata.yaml`` says which storage files make up the bag; the topics, types, definitions and
messages come from the storage files themselves (each opened with rosbags' storage readers).
rosbag2 does the same: a bag recorded by ``ros2 bag record`` keeps QoS in its ``metadata.yaml``
that is written differently from the QoS in its storage (``deadline: {sec: 0}`` against
``2147483647``), and a reader that pairs the two by equality reads nothing. Whenever the storage
holds fewer messages for a topic than ``metadata.yaml`` counts, the reader says so, naming the
topic and the reason (``BagReader.warnings``, also logged).
"""

from __future__ import annotations

import heapq
import logging
from collections.abc import Iterable, Iterator
from contextlib import ExitStack
from pathlib import Path
from typing import Any

from ._metadata import METADATA, BagError, TopicInfo, qos_from_bag, qos_profiles_yaml
from ._types import resolve_type

__all__ = ["BagReader"]

_log = logging.getLogger("aiorobot.bag")

_STORAGES = {"mcap": ".mcap", "sqlite3": ".db3"}


class BagReader:
    """An open rosbag2 directory: its topics, time range and messages in time order.

    ``messages()`` yields ``(topic, time_ns, cdr_bytes)``; ``message_type(topic)`` is the
    aiorobot message class to decode a topic with, or ``None`` when neither aiorobot nor the
    bag's own message definition knows the type (such topics play as raw bytes to nobody).
    ``warnings`` lists, one line each, every topic the bag yields fewer messages of than its
    ``metadata.yaml`` counts, with the reason.
    """

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path)
        if not self.path.exists():
            raise BagError(f"{self.path}: no such bag directory")
        if not self.path.is_dir():
            raise BagError(f"{self.path}: expected a rosbag2 directory (with {METADATA}), found a file")
        if not (self.path / METADATA).exists():
            hint = (
                f"; it holds MCAP files, so it may be a recording that did not finish: run `aiorobot bag reindex {self.path}`"
                if any(self.path.glob("*.mcap"))
                else ""
            )
            raise BagError(f"{self.path}: not a rosbag2 directory (no {METADATA}){hint}")
        self._meta = _metadata_of(self.path)
        self._stack = ExitStack()
        try:
            self._storages = self._open_storages()
        except BaseException:
            self._stack.close()
            raise
        self._types: dict[str, tuple[Any, str]] = {}
        self._start_ns: int | None = None
        self._definitions: dict[str, tuple[str, str] | None] = {}
        self.topics: list[TopicInfo] = []
        self.warnings: list[str] = []
        self._collect_topics()

    # -- opening ---------------------------------------------------------------------------

    def _open_storages(self) -> list[Any]:
        from rosbags.rosbag2 import Reader
        from rosbags.rosbag2.errors import ReaderError

        meta = self._meta
        where = f"{self.path / METADATA}"
        storage = meta["storage_identifier"]
        mode = str(meta.get("compression_mode") or "").lower()
        fmt = str(meta.get("compression_format") or "")
        if mode not in ("", "none", "file", "message"):
            raise BagError(f"{where}: compression_mode: expected '', 'file' or 'message', found {mode!r}")
        if mode in ("file", "message") and fmt != "zstd":
            raise BagError(f"{where}: compression_format: expected 'zstd' (the only format rosbag2 writes), found {fmt!r}")
        self._message_compressed = mode == "message"
        storages = []
        for rel in meta["relative_file_paths"]:
            file = self.path / Path(str(rel)).name
            if not file.exists():
                raise BagError(f"{where}: relative_file_paths names {rel!r}, which is not in {self.path}")
            if mode == "file":
                file = self._decompressed(file)
            if file.suffix != _STORAGES[storage]:
                raise BagError(f"{where}: storage_identifier is {storage!r}, so expected {_STORAGES[storage]} files, found {file.name}")
            reader = Reader(file)
            try:
                reader.open()
            except ReaderError as err:
                raise BagError(
                    f"{file}: cannot read the bag ({err}); if a recording was interrupted, run `aiorobot bag reindex {self.path}`"
                ) from None
            self._stack.callback(reader.close)
            storages.append(reader)
        return storages

    def _decompressed(self, file: Path) -> Path:
        """A zstd-compressed storage file (``compression_mode: file``) decompressed into a temporary directory."""
        import shutil
        import tempfile

        tmp = Path(self._stack.enter_context(tempfile.TemporaryDirectory(prefix="aiorobot-bag-")))
        out = tmp / file.stem  # "x.mcap.zstd" -> "x.mcap"
        with file.open("rb") as src, _zstd().open(src, "rb") as inflated, out.open("wb") as dst:
            shutil.copyfileobj(inflated, dst)
        return out

    def _collect_topics(self) -> None:
        from rosbags.interfaces import MessageDefinitionFormat

        stored: dict[str, list[Any]] = {}
        for reader in self._storages:
            for conn in reader.connections:
                stored.setdefault(conn.topic, []).append(conn)
        listed = {}
        for entry in self._meta["topics_with_message_count"]:
            tm = entry.get("topic_metadata") or {}
            listed[str(tm.get("name", ""))] = (str(tm.get("type", "")), int(entry.get("message_count") or 0))
        for name in [*listed, *(t for t in stored if t not in listed)]:
            conns = stored.get(name, [])
            meta_type, meta_count = listed.get(name, ("", 0))
            count = sum(int(c.msgcount) for c in conns)
            if conns:
                first = conns[0]
                type_name = first.msgtype or meta_type
                defined = next((c for c in conns if c.msgdef.format != MessageDefinitionFormat.NONE), None)
                self._definitions[name] = None if defined is None else (defined.msgdef.format.name, defined.msgdef.data)
                profiles = list(getattr(first.ext, "offered_qos_profiles", []) or [])
                qos, qos_text = qos_from_bag(profiles), qos_profiles_yaml(profiles) if profiles else ""
                digest = first.digest
            else:
                type_name, digest, qos, qos_text = meta_type, "", qos_from_bag([]), ""
                self._definitions[name] = None
            self.topics.append(TopicInfo(name, type_name, digest, qos, count, qos_text=qos_text))
            if count < meta_count:
                reason = (
                    "no storage file holds the topic"
                    if not conns
                    else f"its storage files hold only {count}; {METADATA} is wrong or a file was cut short"
                )
                self._warn(f"{self.path}: topic {name}: {METADATA} counts {meta_count} messages, {reason}")

    def _warn(self, text: str) -> None:
        self.warnings.append(text)
        _log.warning("bag: %s", text)

    # -- the open bag ----------------------------------------------------------------------

    def __enter__(self) -> BagReader:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        self._stack.close()

    def __repr__(self) -> str:
        return f"<BagReader {self.path} topics={len(self.topics)} messages={self.message_count}>"

    @property
    def message_count(self) -> int:
        """Messages the storage files hold (what ``messages()`` yields)."""
        return sum(t.message_count for t in self.topics)

    @property
    def metadata_message_count(self) -> int:
        """The total ``metadata.yaml`` states."""
        return int(self._meta.get("message_count") or 0)

    @property
    def start_ns(self) -> int:
        """The first message's time: neither ``metadata.yaml``'s ``starting_time`` nor an MCAP file's
        statistics, which can both be later (libmcap leaves a message stamped 0 out of them)."""
        if self._start_ns is None:
            first = next(self.messages(), None)
            self._start_ns = first[1] if first is not None else 0
        return self._start_ns

    @property
    def end_ns(self) -> int:
        """The last message's time."""
        times = [int(r.end_time) - 1 for r in self._storages if r.message_count]  # rosbags' end is exclusive
        return max([*times, self.start_ns]) if times else 0

    @property
    def duration_ns(self) -> int:
        return max(0, self.end_ns - self.start_ns)

    @property
    def storage(self) -> str:
        return str(self._meta["storage_identifier"])

    @property
    def files(self) -> list[Path]:
        return [self.path / Path(str(p)).name for p in self._meta["relative_file_paths"]]

    def messages(self, topics: Iterable[str] | None = None, *, start_ns: int | None = None) -> Iterator[tuple[str, int, bytes]]:
        """Messages of ``topics`` (all when None) at or after ``start_ns``, in time order (across files too)."""
        wanted = None if topics is None else set(topics)
        streams = []
        for reader in self._storages:
            conns = [c for c in reader.connections if wanted is None or c.topic in wanted]
            if conns:
                streams.append(((int(t), c.topic, data) for c, t, data in reader.messages(connections=conns, start=start_ns)))
        inflate = _zstd().decompress if self._message_compressed else None
        for time_ns, topic, data in heapq.merge(*streams, key=lambda m: m[0]):
            yield topic, time_ns, bytes(inflate(data) if inflate else data)

    def message_type(self, topic: str) -> Any:
        """The aiorobot class for ``topic``'s type, registering the bag's definition if needed; None if unknown
        (``type_problem(topic)`` then says why)."""
        return self._resolved(topic)[0]

    def type_problem(self, topic: str) -> str:
        """Why ``topic``'s type cannot be known (``""`` when it can)."""
        return self._resolved(topic)[1]

    def _resolved(self, topic: str) -> tuple[Any, str]:
        if topic not in self._types:
            info = next((t for t in self.topics if t.name == topic), None)
            if info is None:
                raise BagError(f"{self.path}: no topic {topic} in the bag (topics: {', '.join(t.name for t in self.topics)})")
            self._types[topic] = resolve_type(info.type, self._definitions.get(topic))
        return self._types[topic]

    def definition(self, topic: str) -> tuple[str, str] | None:
        """``(format, text)`` of the message definition the bag stores for ``topic`` (format ``MSG`` or ``IDL``); None without one."""
        return self._definitions.get(topic)


def _zstd() -> Any:
    try:
        from compression import zstd  # type: ignore[import-not-found]  # Python 3.14
    except ImportError:
        from backports import zstd  # type: ignore[import-not-found,no-redef]  # rosbags' own dependency
    return zstd


def _metadata_of(path: Path) -> dict[str, Any]:
    """``metadata.yaml``'s ``rosbag2_bagfile_information``, checked; a bad file is one BagError naming the key."""
    from ruamel.yaml import YAML
    from ruamel.yaml.error import YAMLError

    where = path / METADATA
    try:
        doc = YAML(typ="safe").load(where.read_text(encoding="utf8"))
    except (YAMLError, UnicodeDecodeError) as err:
        raise BagError(f"{where}: not valid YAML ({str(err).splitlines()[0]})") from None
    info = doc.get("rosbag2_bagfile_information") if isinstance(doc, dict) else None
    if not isinstance(info, dict):
        raise BagError(f"{where}: expected a mapping under 'rosbag2_bagfile_information', found {type(info).__name__}")

    def need(key: str, kind: type, what: str) -> Any:
        value = info.get(key)
        if not isinstance(value, kind):
            raise BagError(f"{where}: rosbag2_bagfile_information.{key}: expected {what}, found {value!r}")
        return value

    storage = need("storage_identifier", str, "'mcap' or 'sqlite3'")
    if storage not in _STORAGES:
        raise BagError(f"{where}: rosbag2_bagfile_information.storage_identifier: expected 'mcap' or 'sqlite3', found {storage!r}")
    need("relative_file_paths", list, "a list of storage file names")
    topics = info.get("topics_with_message_count") or []
    if not isinstance(topics, list) or not all(isinstance(t, dict) for t in topics):
        raise BagError(f"{where}: rosbag2_bagfile_information.topics_with_message_count: expected a list of mappings, found {topics!r}")
    for i, entry in enumerate(topics):
        fmt = (entry.get("topic_metadata") or {}).get("serialization_format", "cdr")
        if fmt != "cdr":
            raise BagError(f"{where}: topics_with_message_count[{i}].topic_metadata.serialization_format: expected 'cdr', found {fmt!r}")
    return dict(info, topics_with_message_count=topics)
