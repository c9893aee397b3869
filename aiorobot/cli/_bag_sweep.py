"""``aiorobot bag sweep RUN --node module:Class [--params f.yaml] -p NAME:=VALUE ... [--jobs N] [--plot out.png]``.

A parameter given several times with ``-p`` is swept (the variants are the product over the
names); each variant is a lock-step replay of the bag in its own worker process
(:func:`aiorobot.bag.sweep`). The table gives, per variant and output topic, messages, rate,
latency and, for odometry, the position RMSE against ``--reference`` (``/ground_truth/odom``).
Every variant's nodes are built once before any worker starts, so a bad argument or parameter is
one line and status 2; a variant that fails in its worker is a row saying why, and status 1.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path
from typing import Any

__all__ = ["add_sweep_arguments", "build_variant_nodes", "sweep_main"]


def add_sweep_arguments(sub: Any) -> None:
    from ._bag_check import _node_spec, _param

    sweep = sub.add_parser(
        "sweep", help="replay a bag into parameter variants of nodes, in parallel, and tabulate their figures",
        description="Replay the bag into the nodes once per parameter variant (a -p NAME given several times is swept) "
        "in parallel worker processes, and print each variant's figures per output topic.")
    sweep.add_argument("bag", type=Path, metavar="RUN", help="the recorded bag directory")
    sweep.add_argument("--node", dest="nodes", action="append", type=_node_spec, required=True, metavar="module:Class",
                       help="a node to run (repeat for several)")
    sweep.add_argument("--params", dest="params_file", type=Path, metavar="FILE", help="a ROS 2 parameter file for every variant")
    sweep.add_argument("-p", "--param", dest="params", action="append", type=_param, default=[], metavar="NAME:=VALUE",
                       help="a parameter value; give a NAME several times to sweep it")
    sweep.add_argument("--topics", nargs="+", default=None, metavar="TOPIC", help="outputs to report (default: all the bag holds)")
    sweep.add_argument("--reference", default="/ground_truth/odom", metavar="TOPIC",
                       help="odometry to compute the position RMSE against (default /ground_truth/odom)")
    sweep.add_argument("-j", "--jobs", type=int, default=0, metavar="N", help="worker processes (default: one per core)")
    sweep.add_argument("--plot", type=Path, metavar="PNG", help="also draw each variant's RMSE (or rate) as bars (needs matplotlib)")


def build_variant_nodes(specs: tuple[str, ...], base_args: tuple[str, ...], variant: tuple[str, ...]) -> list[Any]:
    """The nodes of one variant (module level, so a worker process can be handed it)."""
    from ._run_node import build_node

    ros_args = ["--ros-args", *base_args]
    for item in variant:
        ros_args += ["-p", item]
    return [build_node(spec, ros_args) for spec in specs]


def sweep_main(args: argparse.Namespace) -> int:
    import functools

    from aiorobot.bag import BagError, BagReader, sweep, variants_from_params

    from ._run_node import _UsageError

    from ._bag_check import usage_error

    def usage(text: str) -> int:
        return usage_error("sweep", text)

    base: tuple[str, ...] = ()
    if args.params_file is not None:
        if not args.params_file.is_file():
            return usage(f"--params: no such file {str(args.params_file)!r}")
        base = ("--params-file", str(args.params_file))
    if args.jobs < 0:
        return usage(f"--jobs: expected a number of processes >= 1, found {args.jobs}")
    if args.plot is not None:
        try:
            import matplotlib  # noqa: F401
        except ImportError:
            return usage("--plot needs matplotlib, which is not installed; pip install 'aiorobot[plot]'")
    variants = variants_from_params(args.params)
    build = functools.partial(build_variant_nodes, tuple(args.nodes), base)
    try:
        with BagReader(args.bag) as reader:
            if args.reference and not any(t.name == args.reference for t in reader.topics):
                print(f"aiorobot bag sweep: warning: {args.bag} has no {args.reference}: no RMSE is computed", file=sys.stderr)
        for variant in variants:
            build(variant)  # every variant's parameters checked here, before any worker starts
    except (BagError, _UsageError) as err:
        return usage(str(err))
    results = sweep(str(args.bag), build, variants, outputs=args.topics, reference=args.reference, jobs=args.jobs)
    print(table(results))
    if args.plot is not None:
        _plot(results, args.plot)
        print(f"plot written to {args.plot}")
    return 1 if any(r.error for r in results) else 0


def _short(text: str, width: int = 60) -> str:
    return text if len(text) <= width else text[: width - 3] + "..."


def table(results: list[Any]) -> str:
    """The variants (numbered, with their parameters) and one row per variant and output topic."""
    lines = [f"#{i}: {_short(' '.join(r.params) or '(the parameters as given)', 100)}" for i, r in enumerate(results, 1)]
    rows = [("variant", "topic", "messages", "rate Hz", "latency ms", "RMSE m", "wall s")]
    for i, r in enumerate(results, 1):
        if r.error:
            rows.append((f"#{i}", "-", "-", "-", "-", "-", f"{r.wall_sec:.1f}  failed: {r.error}"))
        for f in r.figures:
            rmse = "-" if math.isnan(f.rmse_m) else f"{f.rmse_m:.4f}"
            rows.append((f"#{i}", f.topic, str(f.messages), f"{f.rate_hz:.1f}", f"{f.latency_sec * 1e3:.3f}", rmse, f"{r.wall_sec:.1f}"))
        if not r.error and not r.figures:
            rows.append((f"#{i}", "(no output topic in the bag)", "-", "-", "-", "-", f"{r.wall_sec:.1f}"))
    widths = [max(len(row[c]) for row in rows) for c in range(6)]
    for row in rows:
        lines.append("  ".join(cell.ljust(w) if c < 2 else cell.rjust(w) for c, (cell, w) in enumerate(zip(row, widths))) + "  " + row[6])
    return "\n".join(lines)


def _plot(results: list[Any], out: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    topics = sorted({f.topic for r in results for f in r.figures})
    fig, axes = plt.subplots(len(topics) or 1, 1, figsize=(8, 2.5 * max(1, len(topics))), squeeze=False)
    for ax, topic in zip(axes[:, 0], topics):
        figs = [next((f for f in r.figures if f.topic == topic), None) for r in results]
        use_rmse = any(f is not None and not math.isnan(f.rmse_m) for f in figs)
        values = [(f.rmse_m if use_rmse else f.rate_hz) if f is not None else math.nan for f in figs]
        ax.bar([f"#{i}" for i in range(1, len(results) + 1)], values)
        ax.set_title(topic)
        ax.set_ylabel("RMSE m" if use_rmse else "rate Hz")
    fig.tight_layout()
    fig.savefig(out)
    plt.close(fig)
