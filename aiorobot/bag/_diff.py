"""Message-by-message, field-by-field comparison of what a bag recorded with what a replay produced.

The pure half of ``aiorobot bag check`` (no runtime, no files): two lists of serialised
messages per topic go in, a :class:`DiffReport` comes out. Messages are paired by their order
on the topic. Identical CDR bytes are equal without decoding (the usual case, and the fast
one); otherwise both are decoded and flattened to ``field.path[i] -> value`` and compared with
the tolerance of the most specific matching ``TOPIC.FIELD`` (a prefix covers its sub-fields:
``/odom.pose`` covers ``pose.pose.position.x``). Numbers (and booleans) differ by their
absolute difference; strings, and arrays of different lengths, differ by ``inf``.
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

__all__ = ["DiffReport", "FieldDifference", "TopicDiff", "compare_topics", "flatten", "parse_tolerance"]


def parse_tolerance(text: str) -> tuple[str, str, float]:
    """``"/odom.pose.pose.position.x=1e-6"`` -> ``("/odom", "pose.pose.position.x", 1e-6)``.

    ``TOPIC=ABS`` (no field) covers every field of the topic. ROS topic names hold no ``.``,
    so the topic ends at the first one. A malformed entry raises ValueError saying what was expected.
    """
    where, sep, value = text.rpartition("=")
    if not sep or not where.startswith("/"):
        raise ValueError(f"tolerance: expected /TOPIC.FIELD=ABS such as /odometry/filtered.pose.pose.position.x=1e-6, found {text!r}")
    topic, _, path = where.partition(".")
    try:
        tol = float(value)
    except ValueError:
        raise ValueError(f"tolerance {text!r}: expected a number after '=', found {value!r}") from None
    if not tol >= 0 or math.isinf(tol):
        raise ValueError(f"tolerance {text!r}: expected a finite number >= 0, found {value!r}")
    return topic, path, tol


def flatten(msg: Any, prefix: str = "") -> Iterator[tuple[str, Any]]:
    """``(path, value)`` for every leaf of ``msg``: ``pose.covariance[3]``, ``header.frame_id``, ``name.len``.

    Arrays and sequences give each element and their length (``field.len``), so a length change
    is one difference rather than a shift of every following element.
    """
    for name in type(msg).get_fields_and_field_types():
        yield from _leaves(getattr(msg, name), f"{prefix}{name}")


def _leaves(value: Any, path: str) -> Iterator[tuple[str, Any]]:
    if hasattr(value, "get_fields_and_field_types"):
        yield from flatten(value, path + ".")
    elif isinstance(value, (str, bytes, bool, int, float)):
        yield path, value
    elif hasattr(value, "tolist") or isinstance(value, (list, tuple)):
        items = value.tolist() if hasattr(value, "tolist") else value
        yield f"{path}.len", len(items)
        for i, item in enumerate(items):
            yield from _leaves(item, f"{path}[{i}]")
    else:
        yield path, value


def _error(recorded: Any, now: Any) -> float:
    """The absolute difference of two leaves: 0 when equal, ``inf`` when they are not comparable numbers."""
    if recorded == now or (recorded != recorded and now != now):  # equal, or both NaN
        return 0.0
    numbers = (int, float, bool)
    if isinstance(recorded, numbers) and isinstance(now, numbers):
        diff = abs(float(now) - float(recorded))
        return diff if diff == diff else math.inf  # one side NaN
    return math.inf


@dataclass(frozen=True, slots=True)
class FieldDifference:
    """The first message of a topic where a field is beyond its tolerance."""

    index: int
    stamp_ns: int
    field: str
    recorded: Any
    now: Any


@dataclass(frozen=True, slots=True)
class TopicDiff:
    """One topic compared: counts, messages beyond tolerance, the first difference, max error per field.

    ``max_error`` holds every field with a non-zero error (within tolerance or not).
    """

    topic: str
    recorded: int
    replayed: int
    differing: int
    first: FieldDifference | None
    max_error: Mapping[str, float] = field(default_factory=dict)

    @property
    def passed(self) -> bool:
        return self.recorded == self.replayed and self.differing == 0


@dataclass(frozen=True, slots=True)
class DiffReport:
    """Every output topic compared; ``passed`` when all counts match and every field is within tolerance."""

    topics: tuple[TopicDiff, ...]
    tolerances: tuple[tuple[str, str, float], ...] = ()

    @property
    def passed(self) -> bool:
        return all(t.passed for t in self.topics)

    def tolerance(self, topic: str, path: str) -> float:
        return _tolerance(self.tolerances, topic, path)


def _tolerance(tolerances: Sequence[tuple[str, str, float]], topic: str, path: str) -> float:
    """The tolerance of the longest ``TOPIC.FIELD`` prefix matching ``topic`` and ``path`` (0 without one)."""
    best, best_len = 0.0, -1
    for t_topic, t_path, tol in tolerances:
        if t_topic != topic:
            continue
        if t_path and not (path == t_path or path.startswith(t_path + ".") or path.startswith(t_path + "[")):
            continue
        if len(t_path) > best_len:
            best, best_len = tol, len(t_path)
    return best


def _stamp_ns(msg: Any, time_ns: int) -> int:
    """The message's ``header.stamp`` when it has one, else the time it was recorded."""
    header = getattr(msg, "header", None)
    stamp = getattr(header, "stamp", None)
    if stamp is None:
        return time_ns
    return int(stamp.sec) * 1_000_000_000 + int(stamp.nanosec)


def compare_topics(
    recorded: Mapping[str, Sequence[tuple[int, bytes]]],
    replayed: Mapping[str, Sequence[tuple[int, bytes]]],
    types: Mapping[str, Any],
    tolerances: Sequence[tuple[str, str, float]] = (),
) -> DiffReport:
    """Compare, per topic of ``recorded``, its ``(time_ns, cdr)`` messages with ``replayed``'s in order.

    ``types`` maps each topic to its message class (to decode messages whose bytes differ).
    """
    from aiorobot.msgs import deserialize

    out = []
    for topic in sorted(recorded):
        old, new = recorded[topic], replayed.get(topic, ())
        msg_type = types[topic]
        max_error: dict[str, float] = {}
        differing = 0
        first: FieldDifference | None = None
        for index, ((t_old, b_old), (_, b_new)) in enumerate(zip(old, new)):
            if b_old == b_new:
                continue
            m_old, m_new = deserialize(b_old, msg_type), deserialize(b_new, msg_type)
            leaves_new = dict(flatten(m_new))
            beyond = None
            for path, value in flatten(m_old):
                now = leaves_new.get(path)
                err = _error(value, now)
                if err:
                    max_error[path] = max(max_error.get(path, 0.0), err)
                    if beyond is None and err > _tolerance(tolerances, topic, path):
                        beyond = path, value, now
            if beyond is not None:
                differing += 1
                if first is None:
                    first = FieldDifference(index, _stamp_ns(m_old, t_old), *beyond)
        out.append(TopicDiff(topic, len(old), len(new), differing, first, max_error))
    return DiffReport(tuple(out), tuple(tolerances))

