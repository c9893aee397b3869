"""``aiorobot graph [--dot|--html]``: the running graph's nodes and topics (rqt_graph's data) over zenoh."""

from __future__ import annotations

import argparse

from ._graph_session import add_graph_options, join_graph

__all__ = ["add_arguments", "main"]


def add_arguments(parser: argparse.ArgumentParser) -> None:
    form = parser.add_mutually_exclusive_group()
    form.add_argument("--dot", metavar="FILE", nargs="?", const="-", help="Graphviz output (to FILE, or stdout)")
    form.add_argument("--html", metavar="FILE", help="a self-contained HTML page drawing the graph (SVG), as rqt_graph")
    parser.add_argument("--include-debug", action="store_true", help="--html: also draw /rosout and /parameter_events")
    add_graph_options(parser)


def main(args: argparse.Namespace) -> int:
    import os
    import sys

    from .. import run

    for option in ("html", "dot"):
        path = getattr(args, option)
        if path and path != "-" and not os.path.isdir(os.path.dirname(os.path.abspath(path))):
            print(f"aiorobot graph: error: --{option}: expected a file in an existing directory, found {path!r}",
                  file=sys.stderr)
            return 2
    return run(_main(args))


async def _main(args: argparse.Namespace) -> int:
    async with join_graph(args) as rt:
        graph = rt.graph
        if args.html:
            from ._graph_html import graph_html

            with open(args.html, "w", encoding="utf-8") as f:
                f.write(graph_html(graph, include_debug=args.include_debug))
            print(f"wrote {args.html}: {len(graph.nodes)} nodes, {len(graph.topics)} topics")
            return 0
        if args.dot:
            text = graph.to_dot()
            if args.dot == "-":
                print(text, end="")
            else:
                with open(args.dot, "w") as f:
                    f.write(text)
            return 0
        for n in sorted(graph.nodes, key=lambda n: n.fully_qualified_name):
            print(n.fully_qualified_name)
        for t in graph.topics:
            pubs = ", ".join(p.node for p in t.publishers) or "-"
            subs = ", ".join(s.node for s in t.subscriptions) or "-"
            print(f"  {t.name} [{', '.join(t.types)}]: {pubs} -> {subs}")
        for bad in graph.incompatible_qos:
            print(f"  incompatible QoS on {bad.topic}: {bad.publisher_node} -> {bad.subscription_node} ({bad.reason})")
        return 0
