"""``aiorobot action list|info|send_goal``: ros2 action against a running graph (zenoh)."""

from __future__ import annotations

import argparse

from ._graph_session import UserError, add_graph_options, fill_message, join_graph, message_to_yaml, run_verb

__all__ = ["add_arguments", "main"]


def add_arguments(parser: argparse.ArgumentParser) -> None:
    verbs = parser.add_subparsers(dest="verb", metavar="VERB", required=True)
    p = verbs.add_parser("list", help="actions in the graph")
    p.add_argument("-t", "--show-types", action="store_true")
    add_graph_options(p)
    p = verbs.add_parser("info", help="an action's servers and clients")
    p.add_argument("name")
    add_graph_options(p)
    p = verbs.add_parser("send_goal", help="send a goal given as YAML and wait for the result")
    p.add_argument("name")
    p.add_argument("type", help="e.g. example_interfaces/action/Fibonacci")
    p.add_argument("values", nargs="?", default="{}")
    p.add_argument("-f", "--feedback", action="store_true", help="print feedback messages")
    p.add_argument("--timeout", type=float, default=60.0)
    add_graph_options(p)


def main(args: argparse.Namespace) -> int:
    return run_verb("action", args, _main)


async def _main(args: argparse.Namespace) -> int:
    action_type = goal = None
    if args.verb == "send_goal":
        from ..msgs import get

        try:
            action_type = get(args.type)
            assert hasattr(action_type, "Goal")
        except Exception:
            raise UserError(f"type: expected an action type such as example_interfaces/action/Fibonacci, found {args.type!r}") from None
        goal = fill_message(action_type.Goal, args.values)
    async with join_graph(args) as rt:
        own = {n.get_fully_qualified_name() for n in rt.nodes}
        actions = [a for a in rt.graph.actions if not set(a.servers) | set(a.clients) <= own]
        if args.verb == "list":
            for a in actions:
                print(f"{a.name} [{', '.join(a.types)}]" if args.show_types else a.name)
            return 0
        if args.verb == "info":
            found = next((a for a in actions if a.name == args.name), None)
            if found is None:
                raise UserError(f"unknown action {args.name!r}; 'aiorobot action list' shows the actions")
            print(f"Action: {found.name}")
            print(f"Action clients: {len(found.clients)}")
            for c in found.clients:
                print(f"    {c}")
            print(f"Action servers: {len(found.servers)}")
            for s in found.servers:
                print(f"    {s}")
            return 0
        from .. import Node

        node = rt.add_node(Node("aiorobot_action_send_goal"))
        client = node.create_action_client(action_type, args.name)
        if not await client.wait_for_server(timeout_sec=args.timeout):
            raise UserError(f"no action server for {args.name} [{args.type}] within {args.timeout} s")
        print(f"Waiting for an action server to become available...\nSending goal:\n{message_to_yaml(goal)}")
        handle = await client.send_goal(goal)
        if not handle.accepted:
            print("Goal was rejected.")
            return 1
        print(f"Goal accepted with ID: {handle.goal_id_str.replace('-', '')}\n")
        if args.feedback:
            async for fb in handle.feedback():
                print(f"Feedback:\n{message_to_yaml(fb)}")
        try:
            result = await handle.result(timeout_sec=args.timeout)
        except TimeoutError:
            raise UserError(f"no result from {args.name} within {args.timeout} s") from None
        print(f"Result:\n{message_to_yaml(result)}")
        print(f"Goal finished with status: {handle.status.name}")
        return 0 if handle.status.name == "SUCCEEDED" else 1
