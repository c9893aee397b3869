"""``aiorobot bench latency``: argument parsing and the command's main.

Loaded lazily by the ``aiorobot`` command line (``aiorobot.cli``): this module
provides ``add_arguments(parser)`` and ``main(args) -> int``.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from typing import Any
from ._runner import PARTS

__all__ = ["add_arguments", "main"]


def _positive_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number >= 1, found {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"expected a whole number >= 1, found {text!r}")
    return value


def _parts(text: str) -> list[str]:
    names = [p.strip() for p in text.split(",") if p.strip()]
    for name in names or [text]:
        if name not in PARTS:
            raise argparse.ArgumentTypeError(f"expected one of {', '.join(PARTS)} (comma-separated), found {name!r}")
    return names


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Add the ``latency`` sub-command of ``aiorobot bench`` to ``parser``."""
    sub = parser.add_subparsers(dest="bench_command", metavar="BENCHMARK", title="benchmarks")
    lat = sub.add_parser(
        "latency",
        help="executor, timer, message latency and CPU benchmark (the seed experiment)",
        description=(
            "The seed experiment (50 Hz control beside 150 ms perception every 100 ms) under the "
            "single, threads and aiorobot executor models; priority-loop timer precision; publish -> "
            "callback latency and throughput; the CPU cost of a 100 Hz publisher; tf figures."
        ),
    )
    lat.add_argument("--quick", action="store_true", help="a smoke run of a few seconds (figures mean little)")
    lat.add_argument("--only", type=_parts, metavar="PART", help=f"run only these parts: {', '.join(PARTS)} (comma-separated)")
    lat.add_argument("--repeat", type=_positive_int, default=1, metavar="K", help="run each part K times; report medians")
    lat.add_argument("--json", metavar="FILE", help="write every figure (and the raw control periods) to FILE as JSON")
    lat.add_argument("--plot", metavar="FILE.png", help="draw the control-period distribution per model (needs matplotlib)")
    lat.add_argument("--periods", type=_positive_int, metavar="N", help="control periods per model in the seed part (default 200)")


def _fail(message: str, prog: str = "aiorobot bench latency") -> int:
    print(f"{prog}: error: {message}", file=sys.stderr)
    return 2


def main(args: argparse.Namespace) -> int:
    """Run the benchmark described by ``args``; returns the exit status."""
    if getattr(args, "bench_command", None) != "latency":
        return _fail("expected a benchmark name: latency (see 'aiorobot bench --help')", "aiorobot bench")
    parts = args.only or list(PARTS)
    if args.plot is not None:
        from ._plot import MATPLOTLIB_MISSING, matplotlib_available

        if "seed" not in parts:
            return _fail("--plot draws the seed part's control periods: add seed to --only, or drop --only")
        if not matplotlib_available():
            return _fail(MATPLOTLIB_MISSING)
    for option, path in (("--json", args.json), ("--plot", args.plot)):
        if path is not None and not os.path.isdir(os.path.dirname(os.path.abspath(path))):
            return _fail(f"{option} {path}: the folder {os.path.dirname(os.path.abspath(path))} does not exist")
    from rich.console import Console

    from ._report import print_report
    from ._runner import python_argv, run_benchmark

    from aiorobot._core._logging import setup_logging

    from ._progress import BenchProgress

    setup_logging("warning")  # the parts' nodes say INFO things ("recording /cmd_vel ...") that would tear the bars
    err = Console(stderr=True)
    with BenchProgress(err, len(parts), args.repeat) as progress:
        doc = run_benchmark(
            parts,
            quick=args.quick,
            repeat=args.repeat,
            periods=args.periods,
            command=python_argv(),
            progress=progress,
            fraction=progress.fraction,
        )
    print_report(doc)
    if args.json is not None:
        try:
            with open(args.json, "w", encoding="utf-8") as f:
                json.dump(doc, f, indent=1)
        except OSError as exc:
            return _fail(f"cannot write --json {args.json}: {exc.strerror or exc}")
        err.print(f"[dim]figures written to {args.json}[/dim]")
    if args.plot is not None:
        from ._plot import write_plot

        try:
            write_plot(doc, args.plot)
        except OSError as exc:
            return _fail(f"cannot write --plot {args.plot}: {exc.strerror or exc}")
        err.print(f"[dim]plot written to {args.plot}[/dim]")
    return 1 if _failures(doc) else 0


def _failures(doc: dict[str, Any]) -> list[str]:
    """Parts (and seed models) that could not run."""
    failed = []
    for name, part in doc["parts"].items():
        if "error" in part:
            failed.append(name)
        for model, kinds in part.get("models", {}).items():
            failed += [f"{name}/{model}/{kind}" for kind, res in kinds.items() if "error" in res]
    return failed
