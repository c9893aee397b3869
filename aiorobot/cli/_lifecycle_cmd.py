"""``aiorobot lifecycle nodes|get|set|list``: ros2 lifecycle against a running graph (zenoh).

A lifecycle node is one that serves ``<node>/get_state`` with ``lifecycle_msgs/srv/GetState``
(ros2lifecycle's test); the verbs call its ``~/get_state``, ``~/get_available_transitions``,
``~/get_transition_graph`` and ``~/change_state``. Output is ros2lifecycle's.
"""

from __future__ import annotations

import argparse
import asyncio
from typing import Any

from ._graph_session import UserError, add_graph_options, call_service, cli_node, join_graph, remote_node_names, run_verb

__all__ = ["add_arguments", "main"]


def add_arguments(parser: argparse.ArgumentParser) -> None:
    verbs = parser.add_subparsers(dest="verb", metavar="VERB", required=True)
    p = verbs.add_parser("nodes", help="nodes with a lifecycle")
    p.add_argument("-c", "--count-nodes", action="store_true", help="only the number of lifecycle nodes")
    p = verbs.add_parser("get", help="the current state of one lifecycle node, or of every one")
    p.add_argument("node_name", nargs="?")
    p = verbs.add_parser("set", help="trigger a transition, by label (configure) or id (1)")
    p.add_argument("node_name")
    p.add_argument("transition")
    p = verbs.add_parser("list", help="the transitions available from the node's current state")
    p.add_argument("node_name")
    p.add_argument("-a", "--all", action="store_true", help="every transition of the state machine")
    for sub in verbs.choices.values():
        sub.add_argument("--timeout", type=float, default=5.0, help="seconds to wait for the node's services")
        add_graph_options(sub)


def main(args: argparse.Namespace) -> int:
    return run_verb("lifecycle", args, _main)


def lifecycle_nodes(rt: Any) -> list[str]:
    """The graph's nodes that serve ``<node>/get_state`` as ``lifecycle_msgs/srv/GetState``."""
    services = {s.name: s.types for s in rt.graph.services}
    return [n for n in remote_node_names(rt) if "lifecycle_msgs/srv/GetState" in services.get(f"{n}/get_state", ())]


def _resolve(nodes: list[str], name: str) -> str:
    fqn = name if name.startswith("/") else "/" + name
    if fqn not in nodes:
        raise UserError(f"unknown lifecycle node {name!r}; 'aiorobot lifecycle nodes' shows them")
    return fqn


async def _main(args: argparse.Namespace) -> int:
    from ..msgs.lifecycle_msgs import ChangeState, GetAvailableTransitions, GetState

    async with join_graph(args) as rt:
        nodes = lifecycle_nodes(rt)
        if args.verb == "nodes":
            if args.count_nodes:
                print(len(nodes))
            elif nodes:
                print("\n".join(nodes))
            return 0
        node = cli_node(rt, "aiorobot_lifecycle")
        if args.verb == "get":
            targets = [_resolve(nodes, args.node_name)] if args.node_name else nodes
            states = await asyncio.gather(
                *(call_service(node, GetState, f"{n}/get_state", GetState.Request(), args.timeout) for n in targets)
            )
            for fqn, response in zip(targets, states):
                state = response.current_state
                prefix = "" if args.node_name else f"{fqn}: "
                print(f"{prefix}{state.label} [{state.id}]")
            return 0
        fqn = _resolve(nodes, args.node_name)
        service = "get_transition_graph" if args.verb == "list" and args.all else "get_available_transitions"
        response = await call_service(
            node, GetAvailableTransitions, f"{fqn}/{service}", GetAvailableTransitions.Request(), args.timeout
        )
        transitions = list(response.available_transitions)
        if args.verb == "list":
            for t in transitions:
                print(f"- {t.transition.label} [{t.transition.id}]\n\tStart: {t.start_state.label}\n\tGoal: {t.goal_state.label}")
            return 0
        chosen = next((t.transition for t in transitions if t.transition.label == args.transition), None)
        if chosen is None:
            chosen = next((t.transition for t in transitions if str(t.transition.id) == args.transition), None)
        if chosen is None:
            available = ", ".join(f"{t.transition.label} [{t.transition.id}]" for t in transitions) or "none"
            raise UserError(f"transition {args.transition!r} is not available from {fqn}'s current state; "
                            f"available: {available}")
        result = await call_service(
            node, ChangeState, f"{fqn}/change_state", ChangeState.Request(transition=chosen), args.timeout
        )
        if not result.success:
            raise UserError(f"transitioning {fqn} with {chosen.label} failed")
        print("Transitioning successful")
        return 0
