"""``reindex``: rebuild a bag whose recorder died (SIGKILL, power loss) from its MCAP files.

An MCAP file written chunk by chunk and never finished has no summary, no footer and maybe a
torn last chunk. Reading it as a stream recovers every record up to the last complete one;
the messages are written again into a finished file (which replaces the damaged one; a file
that is whole is left as it is, as ``ros2 bag reindex`` does) and ``metadata.yaml`` is written
from what was recovered, each topic with the QoS profiles its channel holds, every field kept.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from .._core._qos import QoSProfile
from ._metadata import BagError, TopicInfo, qos_from_bag, write_metadata
from ._writer import CHUNK_SIZE

__all__ = ["ReindexResult", "reindex"]

_log = logging.getLogger("aiorobot.bag")


@dataclass(frozen=True, slots=True)
class ReindexResult:
    """Per bag: files rewritten, messages recovered, and whether any file was damaged."""

    files: int
    messages: int
    damaged: int


def reindex(directory: str | Path) -> ReindexResult:
    """Rebuild every ``*.mcap`` file of ``directory`` and its ``metadata.yaml``."""
    path = Path(directory)
    if not path.is_dir():
        raise BagError(f"{path}: expected a bag directory, found {'a file' if path.exists() else 'nothing'}")
    mcaps = sorted(path.glob("*.mcap"), key=_file_index)
    if not mcaps:
        raise BagError(f"{path}: no .mcap files to reindex (only MCAP storage can be reindexed)")
    topics: dict[str, TopicInfo] = {}
    files: list[dict[str, Any]] = []
    damaged = 0
    for mcap_path in mcaps:
        entry, broken = _rewrite(mcap_path, topics)
        files.append(entry)
        damaged += broken
    write_metadata(path, files, list(topics.values()))
    return ReindexResult(len(files), sum(f["message_count"] for f in files), damaged)


def _file_index(p: Path) -> tuple[int, str]:
    stem = p.stem.rpartition("_")[2]
    return (int(stem) if stem.isdigit() else 0, p.name)


def _rewrite(mcap_path: Path, topics: dict[str, TopicInfo]) -> tuple[dict[str, Any], int]:
    from mcap.exceptions import McapError
    from mcap.records import Channel, Footer, Message, Schema
    from mcap.stream_reader import StreamReader

    schemas: dict[int, Schema] = {}
    channels: dict[int, Channel] = {}
    messages: list[Message] = []
    broken = 0
    finished = False
    with open(mcap_path, "rb") as stream:
        try:
            for record in StreamReader(stream, skip_magic=False).records:
                if isinstance(record, Schema):
                    schemas[record.id] = record
                elif isinstance(record, Channel):
                    channels[record.id] = record
                elif isinstance(record, Message):
                    messages.append(record)
                elif isinstance(record, Footer):
                    finished = True
        except (McapError, EOFError, ValueError, OSError) as err:  # torn tail: keep what came before
            broken = 1
            _log.info("%s: stopped at a damaged or unfinished record (%s); %d messages recovered", mcap_path, err, len(messages))
        except Exception as err:  # the decompressor's own errors on a torn chunk
            broken = 1
            _log.info("%s: stopped at a damaged chunk (%s); %d messages recovered", mcap_path, err, len(messages))
    if not broken and not finished:
        broken = 1
        _log.info("%s: ends without a footer (the recording did not finish); %d messages recovered", mcap_path, len(messages))
    if broken:  # an undamaged file stays as it is (ros2 bag reindex writes only metadata.yaml)
        _write_finished(mcap_path, schemas, channels, messages)
    counts: dict[int, int] = {}
    for m in messages:
        counts[m.channel_id] = counts.get(m.channel_id, 0) + 1
    for cid, c in channels.items():
        schema = schemas.get(c.schema_id)
        info = topics.get(c.topic)
        if info is None:
            from aiorobot.msgs import type_hash

            type_name = schema.name if schema is not None else ""
            digest = c.metadata.get("topic_type_hash", "")
            if not digest:
                try:
                    digest = type_hash(type_name)
                except Exception:
                    digest = ""
            qos_text = c.metadata.get("offered_qos_profiles", "")
            qos, readable = _qos_from_text(qos_text, mcap_path, c.topic)
            info = topics[c.topic] = TopicInfo(c.topic, type_name, digest, qos, qos_text=qos_text if readable else "")
        info.message_count += counts.get(cid, 0)
    times = [m.log_time for m in messages]
    start = min(times, default=0)
    return {
        "path": mcap_path.name,
        "start_ns": start,
        "duration_ns": max(times, default=start) - start,
        "message_count": len(messages),
    }, broken


def _write_finished(mcap_path: Path, schemas: dict[int, Any], channels: dict[int, Any], messages: list[Any]) -> None:
    """Write the recovered records into a finished MCAP file that replaces ``mcap_path``."""
    from mcap.writer import CompressionType, Writer

    tmp = mcap_path.with_suffix(".mcap.reindex")
    with open(tmp, "wb") as out:
        writer = Writer(out, chunk_size=CHUNK_SIZE, compression=CompressionType.ZSTD)
        writer.start(profile="ros2", library="aiorobot reindex")
        schema_ids = {sid: writer.register_schema(s.name, s.encoding, s.data) for sid, s in schemas.items()}
        channel_ids = {
            cid: writer.register_channel(c.topic, c.message_encoding, schema_ids.get(c.schema_id, 0), dict(c.metadata))
            for cid, c in channels.items()
        }
        for m in messages:
            if m.channel_id in channel_ids:
                writer.add_message(channel_ids[m.channel_id], log_time=m.log_time, data=m.data, publish_time=m.publish_time, sequence=m.sequence)
        writer.finish()
    tmp.replace(mcap_path)


def _qos_from_text(text: str, where: Path, topic: str) -> tuple[QoSProfile, bool]:
    """The replay QoS of a channel's ``offered_qos_profiles`` text, and whether the text could be read."""
    from rosbags.rosbag2.metadata import parse_qos

    if not text:
        return QoSProfile(), False
    try:
        return qos_from_bag(parse_qos(text)), True
    except Exception as err:  # noqa: BLE001 - a damaged channel record: replay with the default QoS
        _log.warning("%s: topic %s: offered_qos_profiles cannot be read (%s); the default QoS is used", where, topic, err)
        return QoSProfile(), False
