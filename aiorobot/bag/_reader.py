"""Reads rosbag2 directories (MCAP or SQLite3 storage) through rosbags, the independent reader."""

from __future__ import annotations

import logging
from collections.abc import Iterable, Iterator
from pathlib import Path
from typing import Any

from ._metadata import METADATA, BagError, TopicInfo, qos_from_bag

__all__ = ["BagReader"]

_log = logging.getLogger("aiorobot.bag")


class BagReader:
    """An open rosbag2 directory: its topics, time range and messages in time order.

    ``messages()`` yields ``(topic, time_ns, cdr_bytes)``; ``message_type(topic)`` is the
    aiorobot message class to decode a topic with, or ``None`` when neither aiorobot nor the
    bag's own message definition knows the type (such topics play as raw bytes to nobody).
    """

    def __init__(self, path: str | Path) -> None:
        from rosbags.rosbag2 import Reader
        from rosbags.rosbag2.errors import ReaderError

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
        self._reader = Reader(self.path)
        try:
            self._reader.open()
        except ReaderError as err:
            raise BagError(f"{self.path}: cannot read the bag ({err}); if a recording was interrupted, run `aiorobot bag reindex {self.path}`") from None
        self._meta = _metadata_of(self.path)
        self._count = int(self._reader.message_count)
        self._types: dict[str, Any] = {}
        self.topics: list[TopicInfo] = []
        for name, info in self._reader.topics.items():
            conn = next(c for c in self._reader.connections if c.topic == name)
            self.topics.append(
                TopicInfo(
                    name,
                    info.msgtype or "",
                    conn.digest,
                    qos_from_bag(list(getattr(conn.ext, "offered_qos_profiles", []) or [])),
                    int(info.msgcount),
                )
            )

    def __enter__(self) -> BagReader:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        self._reader.close()

    def __repr__(self) -> str:
        return f"<BagReader {self.path} topics={len(self.topics)} messages={self.message_count}>"

    @property
    def message_count(self) -> int:
        return self._count

    @property
    def start_ns(self) -> int:
        return int(self._reader.start_time) if self.message_count else 0

    @property
    def end_ns(self) -> int:
        return int(self._reader.end_time) - 1 if self.message_count else 0  # rosbags' end is exclusive

    @property
    def duration_ns(self) -> int:
        return max(0, self.end_ns - self.start_ns)

    @property
    def storage(self) -> str:
        return str(self._meta.get("storage_identifier", "?"))

    @property
    def files(self) -> list[Path]:
        return [self.path / p for p in self._meta.get("relative_file_paths", [])]

    def messages(self, topics: Iterable[str] | None = None, *, start_ns: int | None = None) -> Iterator[tuple[str, int, bytes]]:
        """Messages of ``topics`` (all when None) at or after ``start_ns``, in time order."""
        wanted = None if topics is None else set(topics)
        conns = [c for c in self._reader.connections if wanted is None or c.topic in wanted]
        if not conns:
            return
        for conn, time_ns, data in self._reader.messages(connections=conns, start=start_ns):
            yield conn.topic, int(time_ns), bytes(data)

    def message_type(self, topic: str) -> Any:
        """The aiorobot class for ``topic``'s type, registering the bag's definition if needed; None if unknown."""
        if topic in self._types:
            return self._types[topic]
        info = next((t for t in self.topics if t.name == topic), None)
        if info is None:
            raise BagError(f"{self.path}: no topic {topic} in the bag (topics: {', '.join(t.name for t in self.topics)})")
        self._types[topic] = _resolve_type(info.type, self._definition(topic))
        return self._types[topic]

    def _definition(self, topic: str) -> str:
        conn = next(c for c in self._reader.connections if c.topic == topic)
        msgdef = getattr(conn, "msgdef", None)
        return str(getattr(msgdef, "data", "") or "")


def _metadata_of(path: Path) -> dict[str, Any]:
    from ruamel.yaml import YAML

    doc = YAML(typ="safe").load((path / METADATA).read_text(encoding="utf8"))
    return dict(doc.get("rosbag2_bagfile_information", {})) if isinstance(doc, dict) else {}


def _resolve_type(type_name: str, definition: str) -> Any:
    """The aiorobot message class named ``type_name``; unknown ones are registered from ``definition``."""
    from aiorobot import msgs

    try:
        return msgs.get(type_name)
    except (KeyError, LookupError, ValueError):
        pass
    if not definition:
        _log.warning("bag: message type %s is unknown and the bag holds no definition for it; its messages are skipped", type_name)
        return None
    try:
        _register_definition(type_name, definition)
        return msgs.get(type_name)
    except Exception as err:  # a definition aiorobot cannot parse: play nothing rather than wrong data
        _log.warning("bag: message type %s is unknown and its definition in the bag could not be used (%s); its messages are skipped", type_name, err)
        return None


def _register_definition(type_name: str, definition: str) -> None:
    """Register a concatenated ``ros2msg`` definition (main text, then ``MSG: pkg/Type`` blocks), dependencies first."""
    from aiorobot import msgs

    blocks = definition.split("=" * 80 + "\n")
    parts: list[tuple[str, str]] = [(type_name, blocks[0])]
    for block in blocks[1:]:
        header, _, text = block.partition("\n")
        if not header.startswith("MSG: "):
            raise ValueError(f"unexpected block header {header!r} in the definition of {type_name}")
        name = header[5:].strip()
        pkg, _, short = name.rpartition("/")
        parts.append((f"{pkg.split('/')[0]}/msg/{short}", text))
    for name, text in reversed(parts):
        try:
            msgs.get(name)
        except (KeyError, LookupError, ValueError):
            msgs.register_msg(text, name)
