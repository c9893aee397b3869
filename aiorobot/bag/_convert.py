"""``convert``: rosbag2's ``ros2 bag convert`` — input bags merged in time order into the output bags
an output-options YAML describes (split by topic, filtered, storage changed, compressed, cut into files).

The YAML is rosbag2's: a top-level ``output_bags`` list, each entry ``StorageOptions`` +
``RecordOptions`` keys. What aiorobot reads:

- ``uri`` (required), ``storage_id`` (``mcap``, the default, or ``sqlite3``),
  ``max_bagfile_size`` (bytes), ``max_bagfile_duration`` (seconds);
- topic selection as ``ros2 bag record``: ``all_topics``, ``topics``, ``topic_types``, ``regex``;
  ``exclude_regex``, ``exclude_topics``, ``exclude_topic_types``; service-event topics
  (``.../_service_event``) only through ``all_services`` / ``services`` / ``exclude_services``;
- compression: ``compression_mode: file`` or ``message`` with ``compression_format: zstd`` is
  rosbag2's own compression (``<file>.zstd`` files, or each message); ``storage_preset_profile:
  zstd_fast`` / ``zstd_small``, or ``compression_format: zstd`` / ``lz4`` without a mode (or with
  ``chunk``), give MCAP chunk compression, which rosbags, mcap and ``ros2 bag`` read directly.

Keys rosbag2 accepts that change nothing here (``storage_config_uri``, ``compression_queue_size``,
``compression_threads``, ``include_hidden_topics``, ``include_unpublished_topics``,
``rmw_serialization_format`` when ``cdr``) are accepted; any other key is an error naming the file,
the entry and the nearest valid key. An output that selects no topic is reported, not left silent.
"""

from __future__ import annotations

import difflib
import heapq
import re
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ._metadata import BagError
from ._reader import BagReader
from ._writer import BagWriter

__all__ = ["ConvertResult", "OutputBag", "convert", "read_output_options"]

_SERVICE_EVENT = "/_service_event"
_NO_EFFECT = {"storage_config_uri", "compression_queue_size", "compression_threads", "include_hidden_topics",
              "include_unpublished_topics", "rmw_serialization_format"}
_KEYS = {"uri", "storage_id", "max_bagfile_size", "max_bagfile_duration", "storage_preset_profile", "all_topics", "topics",
         "topic_types", "all_services", "services", "regex", "exclude_regex", "exclude_topics", "exclude_topic_types",
         "exclude_services", "compression_mode", "compression_format", *_NO_EFFECT}
_PRESETS = {"": "none", "none": "none", "zstd_fast": "zstd", "zstd_small": "zstd", "fastwrite": "none", "resilient": "none"}


@dataclass(frozen=True, slots=True)
class OutputBag:
    """One entry of ``output_bags``: where to write, how, and which topics."""

    uri: str
    storage: str = "mcap"
    max_bagfile_size: int = 0
    max_bagfile_duration_sec: float = 0.0
    compression: str = "none"
    compression_mode: str = ""
    all_topics: bool = False
    topics: tuple[str, ...] = ()
    topic_types: tuple[str, ...] = ()
    regex: str = ""
    exclude_regex: str = ""
    exclude_topics: tuple[str, ...] = ()
    exclude_topic_types: tuple[str, ...] = ()
    all_services: bool = False
    services: tuple[str, ...] = ()
    exclude_services: tuple[str, ...] = ()

    def selects(self, topic: str, type_name: str) -> bool:
        """Whether ``topic`` of ``type_name`` goes into this bag (``ros2 bag record``'s topic filter)."""
        if topic.endswith(_SERVICE_EVENT) and "/srv/" in type_name:
            service = topic[: -len(_SERVICE_EVENT)]
            return (self.all_services or service in self.services) and service not in self.exclude_services
        chosen = (
            self.all_topics
            or topic in self.topics
            or type_name in self.topic_types
            or bool(self.regex and re.search(self.regex, topic))
        )
        excluded = (
            topic in self.exclude_topics
            or type_name in self.exclude_topic_types
            or bool(self.exclude_regex and re.search(self.exclude_regex, topic))
        )
        return chosen and not excluded


@dataclass(frozen=True, slots=True)
class ConvertResult:
    """What one output bag received: topics, messages, files; ``skipped`` topics with the reason."""

    output: OutputBag
    topics: tuple[str, ...]
    messages: int
    files: tuple[str, ...]
    skipped: tuple[str, ...] = field(default_factory=tuple)


def read_output_options(path: str | Path) -> list[OutputBag]:
    """The ``output_bags`` of a rosbag2 output-options YAML file; a bad file is one BagError naming the key."""
    from ruamel.yaml import YAML
    from ruamel.yaml.error import YAMLError

    path = Path(path)
    try:
        doc = YAML(typ="safe").load(path.read_text(encoding="utf8"))
    except FileNotFoundError:
        raise BagError(f"{path}: no such output-options file") from None
    except (YAMLError, UnicodeDecodeError) as err:
        raise BagError(f"{path}: not valid YAML ({str(err).splitlines()[0]})") from None
    bags = doc.get("output_bags") if isinstance(doc, dict) else None
    if not isinstance(bags, list) or not bags:
        raise BagError(f"{path}: expected a non-empty list under the top-level key 'output_bags', found {bags!r}")
    return [_output_bag(path, i, entry) for i, entry in enumerate(bags)]


def _output_bag(path: Path, i: int, entry: Any) -> OutputBag:
    where = f"{path}: output_bags[{i}]"
    if not isinstance(entry, dict):
        raise BagError(f"{where}: expected a mapping with at least 'uri', found {entry!r}")
    for key in entry:
        if key not in _KEYS:
            close = difflib.get_close_matches(str(key), sorted(_KEYS), n=1)
            hint = f"; did you mean {close[0]!r}?" if close else ""
            raise BagError(f"{where}: unknown key {key!r}{hint}")

    def get(key: str, kind: type | tuple[type, ...], default: Any, what: str) -> Any:
        value = entry.get(key, default)
        if value is None:
            return default
        if not isinstance(value, kind) or (kind is not bool and isinstance(value, bool)):
            raise BagError(f"{where}.{key}: expected {what}, found {value!r}")
        return value

    def names(key: str) -> tuple[str, ...]:
        value = get(key, list, [], "a list of names")
        if not all(isinstance(v, str) for v in value):
            raise BagError(f"{where}.{key}: expected a list of names, found {value!r}")
        return tuple(value)

    uri = get("uri", str, "", "the output bag directory")
    if not uri:
        raise BagError(f"{where}.uri: required (the output bag directory)")
    storage = get("storage_id", str, "", "'mcap' or 'sqlite3'") or "mcap"
    if storage not in ("mcap", "sqlite3"):
        raise BagError(f"{where}.storage_id: expected 'mcap' or 'sqlite3', found {storage!r}")
    fmt = get("rmw_serialization_format", str, "", "'cdr'")
    if fmt not in ("", "cdr"):
        raise BagError(f"{where}.rmw_serialization_format: expected 'cdr' (the only format aiorobot writes), found {fmt!r}")
    preset = get("storage_preset_profile", str, "", "'zstd_fast', 'zstd_small' or ''")
    if preset not in _PRESETS:
        raise BagError(f"{where}.storage_preset_profile: expected one of {', '.join(repr(p) for p in _PRESETS if p)} or '', found {preset!r}")
    compression = _PRESETS[preset]
    mode = get("compression_mode", str, "", "'' or 'chunk'").lower()
    cfmt = get("compression_format", str, "", "'zstd' or 'lz4'")
    if mode not in ("", "none", "chunk", "file", "message"):
        raise BagError(f"{where}.compression_mode: expected 'file', 'message', 'chunk' or '', found {mode!r}")
    file_mode = mode if mode in ("file", "message") else ""
    if file_mode:
        if cfmt != "zstd":
            raise BagError(f"{where}.compression_format: compression_mode {mode!r} needs 'zstd' (rosbag2's only format), found {cfmt!r}")
        if compression != "none":
            raise BagError(f"{where}: storage_preset_profile {preset!r} compresses the chunks; with compression_mode {mode!r} leave it out")
    elif cfmt:
        if cfmt not in ("zstd", "lz4"):
            raise BagError(f"{where}.compression_format: expected 'zstd' or 'lz4', found {cfmt!r}")
        compression = cfmt
    if storage == "sqlite3" and compression != "none":
        raise BagError(
            f"{where}: {compression} without compression_mode is MCAP chunk compression; for storage_id sqlite3 "
            f"use compression_mode: file or message"
        )
    size = get("max_bagfile_size", int, 0, "a number of bytes >= 0")
    duration = get("max_bagfile_duration", (int, float), 0, "a number of seconds >= 0")
    if size < 0 or duration < 0:
        raise BagError(f"{where}: max_bagfile_size and max_bagfile_duration must be >= 0")
    for key in ("regex", "exclude_regex"):
        try:
            re.compile(get(key, str, "", "a regular expression"))
        except re.error as err:
            raise BagError(f"{where}.{key}: not a regular expression ({err})") from None
    return OutputBag(
        uri=uri, storage=storage, max_bagfile_size=size, max_bagfile_duration_sec=float(duration), compression=compression,
        compression_mode=file_mode,
        all_topics=get("all_topics", bool, False, "true or false"), topics=names("topics"), topic_types=names("topic_types"),
        regex=get("regex", str, "", "a regular expression"), exclude_regex=get("exclude_regex", str, "", "a regular expression"),
        exclude_topics=names("exclude_topics"), exclude_topic_types=names("exclude_topic_types"),
        all_services=get("all_services", bool, False, "true or false"), services=names("services"),
        exclude_services=names("exclude_services"),
    )  # fmt: skip


def convert(inputs: Sequence[str | Path], outputs: Sequence[OutputBag]) -> list[ConvertResult]:
    """Merge ``inputs`` in time order into every output bag, each with its own topics, storage and compression.

    Checks everything first (inputs readable, one type per topic, output directories free), then
    writes. A topic whose type aiorobot cannot know (no definition in the bag) is skipped, named
    in ``ConvertResult.skipped``.
    """
    if not inputs:
        raise BagError("convert: expected at least one input bag")
    readers: list[BagReader] = []
    try:
        for path in inputs:
            readers.append(BagReader(path))
        types: dict[str, tuple[str, Any, Any]] = {}  # topic -> (type name, TopicInfo, class)
        for reader in readers:
            for info in reader.topics:
                seen = types.get(info.name)
                if seen is not None and seen[0] != info.type:
                    raise BagError(f"{reader.path}: topic {info.name} is {info.type}, but {seen[0]} in another input")
                if seen is None or seen[2] is None:  # another input may hold the definition the first lacks
                    known = reader.message_type(info.name)
                    if seen is None or known is not None:
                        types[info.name] = (info.type, info, known)
        uris = [Path(o.uri) for o in outputs]
        for uri in uris:
            if uri.exists():
                raise BagError(f"{uri}: exists already; choose another uri or remove it")
        if len(set(uris)) != len(uris):
            raise BagError("output_bags: two entries write the same uri")
        return _write(readers, types, outputs)
    finally:
        for reader in readers:
            reader.close()


def _write(readers: list[BagReader], types: dict[str, tuple[str, Any, Any]], outputs: Sequence[OutputBag]) -> list[ConvertResult]:
    plans = []
    for out in outputs:
        chosen = [t for t, (type_name, _, _) in types.items() if out.selects(t, type_name)]
        skipped = tuple(t for t in chosen if types[t][2] is None)
        plans.append((out, [t for t in chosen if types[t][2] is not None], skipped))
    writers: list[tuple[BagWriter, set[str]]] = []
    try:
        for out, topics, _ in plans:
            writer = BagWriter(out.uri, storage=out.storage, compression=out.compression, compression_mode=out.compression_mode,
                               max_bag_size=out.max_bagfile_size, max_bag_duration_ns=int(out.max_bagfile_duration_sec * 1e9))
            for topic in topics:
                _, info, _ = types[topic]
                writer.add_topic(topic, info.type, info.qos, qos_text=info.qos_text)
            writers.append((writer, set(topics)))
        wanted = set().union(*(topics for _, topics in writers))
        for topic, t_ns, data in _merged(readers, wanted):
            for writer, topics in writers:
                if topic in topics:
                    writer.write(topic, t_ns, data)
    finally:
        for writer, _ in writers:
            writer.close()
    return [
        ConvertResult(out, tuple(topics), writer.message_count, tuple(f.name for f in writer.files), skipped)
        for (out, topics, skipped), (writer, _) in zip(plans, writers)
    ]


def _merged(readers: list[BagReader], wanted: set[str]) -> Iterator[tuple[str, int, bytes]]:
    streams = [r.messages([t.name for t in r.topics if t.name in wanted]) for r in readers]
    return heapq.merge(*streams, key=lambda m: m[1])
