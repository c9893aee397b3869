"""What ``aiorobot bench latency`` shows while it runs: a bar per part on a terminal, a line per part otherwise."""

from __future__ import annotations

import time
from typing import Any

__all__ = ["BenchProgress"]


class BenchProgress:
    """Progress of a benchmark run, written to ``console`` (rich, stderr).

    On a terminal: an overall bar (parts done of all) and, under it, a bar for the running part
    that fills as the part reports how far it is (``run(..., progress=fraction_callback)``) or
    pulses with its elapsed time when the part cannot tell; each finished part leaves one line
    with its wall time. Elsewhere (a pipe, CI): one "running PART ..." line per part.

    Use as the ``progress`` and ``fraction`` callbacks of :func:`run_benchmark`, inside ``with``.
    """

    def __init__(self, console: Any, parts: int, repeat: int = 1) -> None:
        self._console = console
        self._total = parts * repeat
        self._done = 0
        self._live = console.is_terminal
        self._bar: Any = None
        self._overall: Any = None
        self._part: Any = None
        self._part_name = ""
        self._part_started = 0.0

    def __enter__(self) -> BenchProgress:
        if self._live:
            from rich.progress import BarColumn, Progress, TaskProgressColumn, TextColumn, TimeElapsedColumn

            self._bar = Progress(
                TextColumn("{task.description}"), BarColumn(bar_width=24), TaskProgressColumn(), TimeElapsedColumn(),
                console=self._console, transient=True,
            )
            self._bar.__enter__()
            self._overall = self._bar.add_task(f"parts 0/{self._total}", total=self._total)
        return self

    def __exit__(self, *exc: object) -> None:
        self._finish_part()
        if self._bar is not None:
            self._bar.__exit__(*exc)

    def __call__(self, what: str) -> None:
        """A part starts (``what``: its name, with the repeat when there are several)."""
        self._finish_part()
        self._part_name, self._part_started = what, time.monotonic()
        if self._bar is None:
            self._console.print(f"[dim]running {what} ...[/dim]")
            return
        self._part = self._bar.add_task(f"  {what}", total=None)

    def fraction(self, done: float) -> None:
        """The running part reports that ``done`` (0..1) of it has run."""
        if self._bar is not None and self._part is not None:
            self._bar.update(self._part, total=1.0, completed=min(max(done, 0.0), 1.0))

    def _finish_part(self) -> None:
        if not self._part_name:
            return
        wall = time.monotonic() - self._part_started
        self._done += 1
        if self._bar is not None:
            if self._part is not None:
                self._bar.remove_task(self._part)
                self._part = None
            self._bar.update(self._overall, completed=self._done, description=f"parts {self._done}/{self._total}")
            self._bar.console.print(f"[dim]{self._part_name}: {wall:.1f} s[/dim]")
        self._part_name = ""
