"""``check_bag``: replay a bag's inputs into nodes and compare their outputs with the recording.

:func:`check_bag` runs :func:`._replay.replay` and :func:`._diff.compare_topics` and returns a
:class:`CheckResult`, whose :meth:`~CheckResult.table` is what ``aiorobot bag check`` prints
and whose ``passed`` is its exit status. The ``bag_replay`` pytest fixture calls it too.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

from ._diff import DiffReport, compare_topics, parse_tolerance
from ._reader import BagReader
from ._replay import ReplayResult, replay

__all__ = ["CheckResult", "check_bag"]

#: Fields listed per topic in the max-error table; the rest are counted.
_MAX_FIELDS = 20


@dataclass(frozen=True, slots=True)
class CheckResult:
    """A replay and its comparison with the bag: ``passed`` when every output matched within tolerance."""

    path: str
    replay: ReplayResult
    diff: DiffReport
    wall_sec: float

    @property
    def passed(self) -> bool:
        return self.diff.passed

    @property
    def real_time_factor(self) -> float:
        """Recording seconds replayed per wall second."""
        return self.replay.sim_ns / 1e9 / self.wall_sec if self.wall_sec > 0 else float("inf")

    def table(self) -> str:
        """The report: what was played, then per topic the counts, the first difference and max errors."""
        r, lines = self.replay, []
        lines.append(
            f"{self.path}: played {r.played} messages of {', '.join(r.inputs)} over {_sec(r.sim_ns)} s "
            f"in {self.wall_sec:.2f} s ({self.real_time_factor:.1f}x real time)"
        )
        if r.not_in_bag:
            lines.append(f"not in the bag, so never received: {', '.join(r.not_in_bag)}")
        if r.not_recorded:
            lines.append(f"published but not in the bag, so not compared: {', '.join(r.not_recorded)}")
        rows = [("topic", "recorded", "replayed", "differing", "first difference")]
        for t in self.diff.topics:
            first = "-"
            if t.first is not None:
                f = t.first
                first = f"#{f.index} stamp {_sec(f.stamp_ns)}: {f.field} recorded {f.recorded!r} now {f.now!r}"
            elif t.recorded != t.replayed:
                first = f"#{min(t.recorded, t.replayed)}: {'missing now' if t.replayed < t.recorded else 'extra now'}"
            rows.append((t.topic, str(t.recorded), str(t.replayed), str(t.differing), first))
        widths = [max(len(row[i]) for row in rows) for i in range(4)]
        for row in rows:
            lines.append("  ".join(cell.ljust(w) if i == 0 else cell.rjust(w) for i, (cell, w) in enumerate(zip(row, widths))) + "  " + row[4])
        if any(t.max_error for t in self.diff.topics):
            lines.append("max error per field (tolerance):")
        for t in self.diff.topics:
            fields = sorted(t.max_error.items(), key=lambda kv: _natural(kv[0]))
            for path, err in fields[:_MAX_FIELDS]:
                tol = self.diff.tolerance(t.topic, path)
                lines.append(f"  {t.topic}.{path}  {err:.6g}  ({tol:g}){'' if err <= tol else '  beyond'}")
            if len(fields) > _MAX_FIELDS:
                lines.append(f"  {t.topic}: and {len(fields) - _MAX_FIELDS} more fields")
        if not r.outputs:
            lines.append("no output compared: the nodes publish none of the bag's topics")
        lines.append("PASS: every output matches the recording" if self.passed else "FAIL: the outputs differ from the recording")
        return "\n".join(lines)


def _natural(path: str) -> list[Any]:
    """``covariance[2]`` before ``covariance[10]``."""
    return [int(part) if part.isdigit() else part for part in re.split(r"(\d+)", path)]


def _sec(ns: int) -> str:
    return f"{ns / 1e9:.9f}"


async def check_bag(
    path: str,
    factories: Sequence[Callable[[], Any]],
    *,
    tolerances: Sequence[str | tuple[str, str, float]] = (),
    outputs: Sequence[str] | None = None,
) -> CheckResult:
    """Replay ``path``'s inputs into the nodes ``factories`` build and compare what they publish with the bag.

    ``tolerances``: ``"/TOPIC.FIELD=ABS"`` strings (or parsed triples); a field without one must
    match exactly. ``outputs``: the topics to compare (default: every topic the nodes publish that
    the bag holds, except ``/rosout`` and ``/parameter_events``). Raises :class:`BagError` for a
    bag that cannot be read or nodes that take nothing from it, ValueError for a bad tolerance.
    """
    import time

    parsed = [parse_tolerance(t) if isinstance(t, str) else t for t in tolerances]
    start = time.perf_counter()
    result = await replay(str(path), factories, outputs=outputs)
    wall = time.perf_counter() - start
    with BagReader(path) as reader:
        recorded: dict[str, list[tuple[int, bytes]]] = {t: [] for t in result.outputs}
        for topic, t_ns, data in reader.messages(list(result.outputs)):
            recorded[topic].append((t_ns, data))
    diff = compare_topics(recorded, result.outputs, result.types, parsed)
    return CheckResult(str(path), result, diff, wall)
