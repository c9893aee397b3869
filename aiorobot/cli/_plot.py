"""``aiorobot plot TOPIC.FIELD... [--bag DIR | --duration S] [-o out.png]``: PlotJuggler's habit.

Each argument names a topic and a field path inside its messages, e.g.
``/odom.pose.pose.position.x`` or ``/joint_states.position[0]``; the topic is the longest
prefix that is a topic of the bag (or of the graph). Values are drawn against time (seconds
from the first message) with matplotlib, which the ``plot`` extra installs.
"""

from __future__ import annotations

import argparse
import re
import sys
from pathlib import Path
from typing import Any

from ._parser import positive_seconds, transport_name

__all__ = ["add_arguments", "field_value", "main", "split_series"]

_PART = re.compile(r"^([A-Za-z_][A-Za-z0-9_]*)((?:\[-?\d+\])*)$")


class PlotError(Exception):
    """A series or source that cannot be plotted; the message says which and why."""


def split_series(spec: str, topics: list[str]) -> tuple[str, str]:
    """``"/odom.pose.pose.position.x"`` -> ``("/odom", "pose.pose.position.x")`` against known ``topics``."""
    for topic in sorted(topics, key=len, reverse=True):
        if spec.startswith(topic + ".") or spec.startswith(topic + "["):
            return topic, spec[len(topic) :].lstrip(".")
        if spec == topic:
            raise PlotError(f"{spec}: expected TOPIC.FIELD (a numeric field of {topic}), found only the topic")
    raise PlotError(f"{spec}: no topic of the source is a prefix (topics: {', '.join(sorted(topics)) or 'none'})")


def field_value(msg: Any, path: str) -> float:
    """The number at ``path`` (``a.b[2].c``) inside ``msg``; PlotError naming the part that fails."""
    value = msg
    walked = ""
    for part in path.split("."):
        m = _PART.match(part)
        if m is None:
            raise PlotError(f"{path}: {part!r} is not a field name (expected name or name[index])")
        name, indexes = m.group(1), m.group(2)
        if not hasattr(value, name):
            fields = [f for f in getattr(type(value), "__slots__", ()) if not f.startswith("_")]
            raise PlotError(f"{path}: {type(value).__name__}{' at ' + walked if walked else ''} has no field {name!r}"
                            + (f" (fields: {', '.join(fields)})" if fields else ""))
        value = getattr(value, name)
        walked = f"{walked}.{name}" if walked else name
        for index in re.findall(r"\[(-?\d+)\]", indexes):
            try:
                value = value[int(index)]
            except (IndexError, TypeError):
                raise PlotError(f"{path}: {walked} has no element [{index}]") from None
            walked += f"[{index}]"
    try:
        return float(value)
    except (TypeError, ValueError):
        raise PlotError(f"{path}: {walked} is a {type(value).__name__}, not a number; name a numeric field inside it") from None


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.description = "Plot numeric message fields over time, from a bag or live from the graph."
    parser.add_argument("series", nargs="+", metavar="TOPIC.FIELD", help="e.g. /odom.pose.pose.position.x")
    parser.add_argument("--bag", type=Path, metavar="DIR", help="read from this bag instead of the live graph")
    parser.add_argument("--duration", type=positive_seconds, default=10.0, metavar="S", help="live: record S seconds first (default 10)")
    parser.add_argument("-o", "--output", type=Path, default=Path("plot.png"), metavar="FILE.png", help="image to write (default plot.png)")
    parser.add_argument("--transport", default="zenoh", type=transport_name, metavar="NAME", help="live: how to reach the graph (default zenoh)")


def main(args: argparse.Namespace) -> int:
    from aiorobot.bag import BagError

    try:
        import matplotlib
    except ImportError:
        print("aiorobot plot: error: matplotlib is not installed; pip install 'aiorobot[plot]'", file=sys.stderr)
        return 1
    del matplotlib
    try:
        series = _from_bag(args.bag, args.series) if args.bag else _live(args)
        _draw(series, args.output, title=str(args.bag) if args.bag else "live")
    except (PlotError, BagError, NotImplementedError) as err:
        print(f"aiorobot plot: error: {err}", file=sys.stderr)
        return 1
    total = sum(len(v[0]) for v in series.values())
    print(f"wrote {args.output}: {len(series)} series, {total} points")
    return 0


def _from_bag(path: Path, specs: list[str]) -> dict[str, tuple[list[float], list[float]]]:
    from aiorobot.bag import BagReader
    from aiorobot.msgs import deserialize

    with BagReader(path) as reader:
        names = [t.name for t in reader.topics]
        wanted = {spec: split_series(spec, names) for spec in specs}
        out: dict[str, tuple[list[float], list[float]]] = {spec: ([], []) for spec in specs}
        start = reader.start_ns
        topics = {topic for topic, _ in wanted.values()}
        types = {topic: reader.message_type(topic) for topic in topics}
        for topic, t_ns, data in reader.messages(topics):
            if types[topic] is None:
                raise PlotError(f"{topic}: its type is unknown to aiorobot and the bag carries no usable definition")
            msg = deserialize(data, types[topic])
            for spec, (t, path) in wanted.items():
                if t == topic:
                    out[spec][0].append((t_ns - start) / 1e9)
                    out[spec][1].append(field_value(msg, path))
    return out


def _live(args: argparse.Namespace) -> dict[str, tuple[list[float], list[float]]]:
    import aiorobot

    return aiorobot.run(_collect(args))


async def _collect(args: argparse.Namespace) -> dict[str, tuple[list[float], list[float]]]:
    import asyncio

    from aiorobot import Node, Runtime

    out: dict[str, tuple[list[float], list[float]]] = {spec: ([], []) for spec in args.series}
    async with Runtime(transport=args.transport) as rt:
        await asyncio.sleep(0.5)  # let discovery fill the graph
        topics = {t.name: t.types[0] for t in rt.graph.topics if t.types}
        wanted = {spec: split_series(spec, list(topics)) for spec in args.series}
        node = Node("aiorobot_plot")
        from aiorobot.msgs import get

        start = rt.now().nanoseconds
        for topic in {t for t, _ in wanted.values()}:
            def on_msg(msg: Any, topic: str = topic) -> None:
                now = (rt.now().nanoseconds - start) / 1e9
                for spec, (t, path) in wanted.items():
                    if t == topic:
                        out[spec][0].append(now)
                        out[spec][1].append(field_value(msg, path))

            node.create_subscription(get(topics[topic]), topic, on_msg, 100)
        rt.add_node(node)
        print(f"collecting {args.duration:g} s of {', '.join(args.series)}", file=sys.stderr)
        await rt.spin(duration_sec=args.duration)
    return out


def _draw(series: dict[str, tuple[list[float], list[float]]], output: Path, *, title: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(9, 4.5), dpi=100)
    for spec, (t, v) in series.items():
        ax.plot(t, v, label=f"{spec} ({len(v)})", linewidth=1.2)
    ax.set_xlabel("time (s from the first message)")
    ax.set_title(f"aiorobot plot — {title}")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize=8)
    fig.tight_layout()
    fig.savefig(output)
    plt.close(fig)
