"""rosbag2 ``metadata.yaml`` (version 9, as ROS 2 Jazzy writes it) and QoS profiles in bags."""

from __future__ import annotations

import io
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from .._core._qos import DurabilityPolicy, HistoryPolicy, LivelinessPolicy, QoSProfile, ReliabilityPolicy

__all__ = ["BagError", "TopicInfo", "metadata_text", "qos_from_bag", "qos_profiles_yaml", "qos_to_bag", "write_metadata"]

METADATA = "metadata.yaml"
VERSION = 9


class BagError(Exception):
    """A bag directory or file that cannot be read or written; the message says what and where."""


@dataclass
class TopicInfo:
    """One topic of a bag: its name, type, type hash, QoS and how many messages it holds."""

    name: str
    type: str
    type_hash: str
    qos: QoSProfile
    message_count: int = 0
    extra: dict[str, Any] = field(default_factory=dict)
    #: ``offered_qos_profiles`` as the storage file holds it (YAML text); when set, ``metadata.yaml``
    #: gets these profiles, every field kept, so readers that pair the two by equality (rosbags)
    #: find the topic.
    qos_text: str = ""


def qos_to_bag(qos: QoSProfile) -> Any:
    """``qos`` as rosbags' ``Qos`` (what rosbag2 stores as ``offered_qos_profiles``)."""
    from rosbags.interfaces import Qos, QosDurability, QosHistory, QosLiveliness, QosReliability, QosTime

    def duration(d: Any) -> Any:
        if d is None:
            return QosTime(0, 0)
        ns = int(d.nanoseconds)
        return QosTime(ns // 1_000_000_000, ns % 1_000_000_000)

    return Qos(
        QosHistory.KEEP_ALL if qos.history is HistoryPolicy.KEEP_ALL else QosHistory.KEEP_LAST,
        qos.depth,
        QosReliability.BEST_EFFORT if qos.reliability is ReliabilityPolicy.BEST_EFFORT else QosReliability.RELIABLE,
        QosDurability.TRANSIENT_LOCAL if qos.durability is DurabilityPolicy.TRANSIENT_LOCAL else QosDurability.VOLATILE,
        duration(qos.deadline),
        duration(qos.lifespan),
        QosLiveliness.MANUAL_BY_TOPIC if qos.liveliness is LivelinessPolicy.MANUAL_BY_TOPIC else QosLiveliness.AUTOMATIC,
        duration(qos.liveliness_lease_duration),
        False,
    )


def qos_from_bag(profiles: list[Any]) -> QoSProfile:
    """The QoS to replay a topic with: its first offered profile (rosbag2 play's choice), else the default."""
    from rosbags.interfaces import QosDurability, QosHistory, QosReliability

    if not profiles:
        return QoSProfile()
    p = profiles[0]
    return QoSProfile(
        reliability=ReliabilityPolicy.BEST_EFFORT if p.reliability == QosReliability.BEST_EFFORT else ReliabilityPolicy.RELIABLE,
        durability=DurabilityPolicy.TRANSIENT_LOCAL if p.durability == QosDurability.TRANSIENT_LOCAL else DurabilityPolicy.VOLATILE,
        history=HistoryPolicy.KEEP_ALL if p.history == QosHistory.KEEP_ALL else HistoryPolicy.KEEP_LAST,
        depth=max(1, int(p.depth or 10)),
    )


def qos_yaml(qos: QoSProfile) -> str:
    """The YAML text rosbag2's MCAP storage keeps in a channel's ``offered_qos_profiles``."""
    return qos_profiles_yaml([qos_to_bag(qos)])


def qos_profiles_yaml(profiles: list[Any]) -> str:
    """rosbags ``Qos`` profiles (as a bag holds them, every field kept) as ``offered_qos_profiles`` YAML."""
    from rosbags.rosbag2.metadata import dump_qos_v9

    return _yaml_text(dump_qos_v9(profiles))


def _yaml_text(data: Any) -> str:
    from ruamel.yaml import YAML

    yaml = YAML(typ="safe")
    yaml.default_flow_style = False
    out = io.StringIO()
    yaml.dump(data, out)
    return out.getvalue()


def write_metadata(
    directory: Path,
    files: list[dict[str, Any]],
    topics: list[TopicInfo],
    *,
    storage: str = "mcap",
    compression_mode: str = "",
) -> None:
    """Write ``directory/metadata.yaml`` in rosbag2's version 9 format (atomically: temp file + rename).

    ``files``: one dict per storage file, ``{"path", "start_ns", "duration_ns", "message_count"}``.
    """
    tmp = directory / (METADATA + ".tmp")
    tmp.write_text(metadata_text(files, topics, storage=storage, compression_mode=compression_mode), encoding="utf8")
    tmp.replace(directory / METADATA)


def metadata_text(files: list[dict[str, Any]], topics: list[TopicInfo], *, storage: str = "mcap", compression_mode: str = "") -> str:
    """The ``metadata.yaml`` text (version 9) of a bag made of ``files`` holding ``topics``.

    ``compression_mode``: rosbag2's ``FILE`` or ``MESSAGE`` zstd compression, ``""`` for none.
    """
    from rosbags.rosbag2.metadata import dump_qos_v9, parse_qos

    start = min((f["start_ns"] for f in files if f["message_count"]), default=0)
    end = max((f["start_ns"] + f["duration_ns"] for f in files if f["message_count"]), default=start)
    doc = {
        "rosbag2_bagfile_information": {
            "version": VERSION,
            "storage_identifier": storage,
            "relative_file_paths": [f["path"] for f in files],
            "duration": {"nanoseconds": end - start},
            "starting_time": {"nanoseconds_since_epoch": start},
            "message_count": sum(t.message_count for t in topics),
            "topics_with_message_count": [
                {
                    "topic_metadata": {
                        "name": t.name,
                        "type": t.type,
                        "serialization_format": "cdr",
                        "offered_qos_profiles": dump_qos_v9(parse_qos(t.qos_text) if t.qos_text else [qos_to_bag(t.qos)]),
                        "type_description_hash": t.type_hash,
                    },
                    "message_count": t.message_count,
                }
                for t in topics
            ],
            "compression_format": "zstd" if compression_mode else "",
            "compression_mode": compression_mode,
            "files": [
                {
                    "path": f["path"],
                    "starting_time": {"nanoseconds_since_epoch": f["start_ns"]},
                    "duration": {"nanoseconds": f["duration_ns"]},
                    "message_count": f["message_count"],
                }
                for f in files
            ],
            "custom_data": None,
            "ros_distro": "jazzy",
        }
    }
    return _yaml_text(doc)
