"""The seed experiment's parameters, shared by the three executor models."""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any

__all__ = ["SeedConfig"]


@dataclass(frozen=True, slots=True)
class SeedConfig:
    """A 50 Hz control timer beside a perception timer doing 150 ms of work every 100 ms.

    Every model measures the control callback's start times for ``warmup +
    periods + 1`` callbacks and reports the last ``periods`` periods.
    """

    periods: int = 200
    warmup: int = 10
    control_period_sec: float = 0.02
    perception_period_sec: float = 0.1
    work_sec: float = 0.15

    def __post_init__(self) -> None:
        if self.periods < 1:
            raise ValueError(f"periods must be >= 1, received {self.periods!r}")
        if self.warmup < 0:
            raise ValueError(f"warmup must be >= 0, received {self.warmup!r}")

    @property
    def stamps_needed(self) -> int:
        return self.warmup + self.periods + 1

    @property
    def nominal_ms(self) -> float:
        return self.control_period_sec * 1e3

    def as_dict(self) -> dict[str, Any]:
        return asdict(self)
