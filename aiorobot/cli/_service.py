"""``aiorobot service list|call``: ros2 service against a running graph (zenoh)."""

from __future__ import annotations

import argparse

from ._graph_session import UserError, add_graph_options, fill_message, join_graph, message_to_yaml, run_verb

__all__ = ["add_arguments", "main"]


def add_arguments(parser: argparse.ArgumentParser) -> None:
    verbs = parser.add_subparsers(dest="verb", metavar="VERB", required=True)
    p = verbs.add_parser("list", help="services in the graph")
    p.add_argument("-t", "--show-types", action="store_true")
    add_graph_options(p)
    p = verbs.add_parser("call", help="call a service with a request given as YAML")
    p.add_argument("name")
    p.add_argument("type", help="e.g. example_interfaces/srv/AddTwoInts")
    p.add_argument("values", nargs="?", default="{}")
    p.add_argument("--timeout", type=float, default=10.0)
    add_graph_options(p)


def main(args: argparse.Namespace) -> int:
    return run_verb("service", args, _main)


async def _main(args: argparse.Namespace) -> int:
    srv_type = None
    if args.verb == "call":
        from ..msgs import get

        try:
            srv_type = get(args.type)
            assert hasattr(srv_type, "Request")
        except Exception:
            raise UserError(f"type: expected a service type such as std_srvs/srv/Trigger, found {args.type!r}") from None
        request = fill_message(srv_type.Request, args.values)
    async with join_graph(args) as rt:
        own = {n.get_fully_qualified_name() for n in rt.nodes}
        if args.verb == "list":
            for s in rt.graph.services:
                if set(s.servers) | set(s.clients) <= own:
                    continue
                print(f"{s.name} [{', '.join(s.types)}]" if args.show_types else s.name)
            return 0
        from .. import Node, ServiceError

        node = rt.add_node(Node("aiorobot_service_call"))
        client = node.create_client(srv_type, args.name)
        if not await client.wait_for_service(timeout_sec=args.timeout):
            raise UserError(f"no server for {args.name} [{args.type}] within {args.timeout} s")
        print(f"requester: making request: {request!r}\n")
        try:
            response = await client.call(request, timeout_sec=args.timeout)
        except (ServiceError, TimeoutError) as err:
            raise UserError(str(err)) from None
        print("response:")
        print(message_to_yaml(response), end="")
        return 0
