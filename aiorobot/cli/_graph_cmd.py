"""``aiorobot graph [--dot]``: the running graph's nodes and topics (rqt_graph's data) over zenoh."""

from __future__ import annotations

import argparse

from ._graph_session import add_graph_options, join_graph

__all__ = ["add_arguments", "main"]


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--dot", metavar="FILE", nargs="?", const="-", help="Graphviz output (to FILE, or stdout)")
    add_graph_options(parser)


def main(args: argparse.Namespace) -> int:
    from .. import run

    return run(_main(args))


async def _main(args: argparse.Namespace) -> int:
    async with join_graph(args) as rt:
        graph = rt.graph
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
