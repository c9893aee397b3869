"""``aiorobot node list|info``: ros2 node against a running graph (zenoh)."""

from __future__ import annotations

import argparse

from ._graph_session import UserError, add_graph_options, join_graph, run_verb

__all__ = ["add_arguments", "main"]


def add_arguments(parser: argparse.ArgumentParser) -> None:
    verbs = parser.add_subparsers(dest="verb", metavar="VERB", required=True)
    add_graph_options(verbs.add_parser("list", help="nodes in the graph"))
    p = verbs.add_parser("info", help="a node's publishers, subscriptions, services and actions")
    p.add_argument("name")
    add_graph_options(p)


def main(args: argparse.Namespace) -> int:
    return run_verb("node", args, _main)


async def _main(args: argparse.Namespace) -> int:
    async with join_graph(args) as rt:
        graph = rt.graph
        own = {n.get_fully_qualified_name() for n in rt.nodes}
        nodes = sorted(n.fully_qualified_name for n in graph.nodes if n.fully_qualified_name not in own)
        if args.verb == "list":
            print("\n".join(nodes))
            return 0
        name = args.name if args.name.startswith("/") else "/" + args.name
        if name not in nodes:
            raise UserError(f"unknown node {args.name!r}; 'aiorobot node list' shows the nodes")
        print(name)
        sections = {
            "Subscribers": [(t.name, t.types) for t in graph.topics if any(e.node == name for e in t.subscriptions)],
            "Publishers": [(t.name, t.types) for t in graph.topics if any(e.node == name for e in t.publishers)],
            "Service Servers": [(s.name, s.types) for s in graph.services if name in s.servers],
            "Service Clients": [(s.name, s.types) for s in graph.services if name in s.clients],
            "Action Servers": [(a.name, a.types) for a in graph.actions if name in a.servers],
            "Action Clients": [(a.name, a.types) for a in graph.actions if name in a.clients],
        }
        for title, rows in sections.items():
            print(f"  {title}:")
            for topic, types in rows:
                print(f"    {topic}: {', '.join(types)}")
        return 0
