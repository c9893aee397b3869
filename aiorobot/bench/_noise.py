"""Machine noise beside the figures: CPU steal and load from /proc.

These machines are shared virtual machines: the host steals CPU in bursts and a
stall of 10 ms to 1 s can hit any process. A maximum means nothing without the
steal figure of the same interval, so every part of the benchmark runs inside a
:class:`NoiseMeter` and reports what it saw.

The parsing functions are pure (they take the text of the /proc files), the
meter reads the files. Where /proc does not exist (macOS, Windows) the figures
are ``None``.
"""

from __future__ import annotations

import os
from collections.abc import Awaitable, Callable, Sequence
from dataclasses import asdict, dataclass
from typing import Any

__all__ = [
    "CpuTimes", "NoiseMeter", "NoiseSample", "measure_cases", "noise_between", "parse_loadavg", "parse_proc_stat",
]

_FIELDS = ("user", "nice", "system", "idle", "iowait", "irq", "softirq", "steal")


@dataclass(frozen=True, slots=True)
class CpuTimes:
    """The machine-wide ``cpu`` line of /proc/stat, in clock ticks."""

    user: int
    nice: int
    system: int
    idle: int
    iowait: int
    irq: int
    softirq: int
    steal: int

    @property
    def total(self) -> int:
        # guest and guest_nice are already counted inside user and nice.
        return self.user + self.nice + self.system + self.idle + self.iowait + self.irq + self.softirq + self.steal

    @property
    def busy(self) -> int:
        return self.user + self.nice + self.system + self.irq + self.softirq


def parse_proc_stat(text: str) -> CpuTimes:
    """Read the aggregate ``cpu`` line of /proc/stat.

    Raises ``ValueError`` naming what was expected when the line is missing.
    """
    for line in text.splitlines():
        parts = line.split()
        if parts and parts[0] == "cpu":
            values = [int(v) for v in parts[1:9]]
            values += [0] * (len(_FIELDS) - len(values))  # very old kernels lack steal
            return CpuTimes(*values)
    raise ValueError("expected a line starting with 'cpu ' in /proc/stat, received none")


def parse_loadavg(text: str) -> float:
    """The one-minute load average from the text of /proc/loadavg."""
    try:
        return float(text.split()[0])
    except (IndexError, ValueError):
        raise ValueError(f"expected /proc/loadavg to start with a number, received {text[:40]!r}") from None


@dataclass(frozen=True, slots=True)
class NoiseSample:
    """What the machine did during one interval.

    ``steal_pct``: share of all CPU time stolen by the host; ``busy_pct``: share
    spent in user and system code by every process; ``others_pct``: the part of
    ``busy_pct`` not spent by this process (nor its reaped children), i.e. what
    other programs took from the machine; ``load1``: the one-minute load
    average at the end. Shares are of the whole machine (all CPUs). ``None``
    where /proc is not available.
    """

    wall_sec: float
    steal_pct: float | None
    busy_pct: float | None
    load1: float | None
    others_pct: float | None = None

    def as_dict(self) -> dict[str, Any]:
        return asdict(self)


def noise_between(
    before: CpuTimes, after: CpuTimes, wall_sec: float, load1: float | None, own_ticks: float | None = None
) -> NoiseSample:
    """The noise figures of the interval between two /proc/stat readings.

    ``own_ticks``: CPU time this process used in the interval, in clock ticks;
    with it, ``others_pct`` is the busy share this process did not account for.
    """
    total = after.total - before.total
    if total <= 0:
        return NoiseSample(wall_sec=wall_sec, steal_pct=0.0, busy_pct=0.0, load1=load1, others_pct=0.0)
    busy = 100.0 * (after.busy - before.busy) / total
    others = None if own_ticks is None else max(0.0, busy - 100.0 * own_ticks / total)
    return NoiseSample(
        wall_sec=wall_sec,
        steal_pct=100.0 * (after.steal - before.steal) / total,
        busy_pct=busy,
        load1=load1,
        others_pct=others,
    )


def _own_cpu_sec() -> float:
    t = os.times()
    return t.user + t.system + t.children_user + t.children_system


def _clock_ticks_per_sec() -> float:
    try:
        return float(os.sysconf("SC_CLK_TCK"))
    except (AttributeError, ValueError, OSError):  # pragma: no cover - non-POSIX
        return 100.0


def _read(path: str) -> str | None:
    try:
        with open(path, encoding="ascii") as f:
            return f.read()
    except OSError:
        return None


class NoiseMeter:
    """Context manager measuring steal and load over the block it wraps.

    >>> with NoiseMeter() as meter:
    ...     pass
    >>> meter.result.wall_sec >= 0.0
    True
    """

    def __init__(self) -> None:
        self._before: CpuTimes | None = None
        self._t0 = 0.0
        self._own0 = 0.0
        self.result: NoiseSample | None = None

    def __enter__(self) -> NoiseMeter:
        import time

        text = _read("/proc/stat")
        self._before = parse_proc_stat(text) if text is not None else None
        self._t0 = time.monotonic()
        self._own0 = _own_cpu_sec()
        return self

    def __exit__(self, *exc: object) -> None:
        import time

        wall = time.monotonic() - self._t0
        text = _read("/proc/stat")
        load_text = _read("/proc/loadavg")
        load1 = parse_loadavg(load_text) if load_text is not None else None
        if text is None or self._before is None:
            self.result = NoiseSample(wall_sec=wall, steal_pct=None, busy_pct=None, load1=load1)
        else:
            own_ticks = (_own_cpu_sec() - self._own0) * _clock_ticks_per_sec()
            self.result = noise_between(self._before, parse_proc_stat(text), wall, load1, own_ticks)


def cpu_count() -> int:
    return os.cpu_count() or 1


def measure_cases(
    measure: Callable[[str, float], Awaitable[dict[str, Any]]], cases: Sequence[str], duration_sec: float
) -> tuple[list[dict[str, Any]], dict[str, Any]]:
    """``await measure(case, duration_sec)`` for each case in one event loop, each row with its
    noise beside it (``row["noise"]``); returns the rows and the noise of the whole run."""
    import aiorobot

    async def each() -> list[dict[str, Any]]:
        rows = []
        for case in cases:
            with NoiseMeter() as meter:
                row = await measure(case, duration_sec)
            assert meter.result is not None
            row["noise"] = meter.result.as_dict()
            rows.append(row)
        return rows

    with NoiseMeter() as meter:
        rows = aiorobot.run(each())
    assert meter.result is not None
    return rows, meter.result.as_dict()
