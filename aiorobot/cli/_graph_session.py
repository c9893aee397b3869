"""What the graph commands share: joining the graph over zenoh or DDS, and messages as YAML."""

from __future__ import annotations

import argparse
import asyncio
import os
import sys
import time
from collections.abc import AsyncIterator, Callable, Coroutine
from contextlib import asynccontextmanager
from typing import Any

import numpy as np

__all__ = [
    "run_verb",
    "UserError",
    "add_graph_options",
    "call_service",
    "cli_node",
    "fill_message",
    "join_graph",
    "message_to_yaml",
    "remote_node_names",
    "resolve_node",
    "to_plain",
]

#: Discovery is complete once no liveliness token has arrived for this long.
QUIET_SEC = 0.15
#: with nothing discovered yet, wait this long before calling the graph empty: the session's link to
#: the router can take longer than QUIET_SEC to come up, and `topic list` then printed nothing (1 run in 8)
EMPTY_QUIET_SEC = 1.0
DISCOVERY_MAX_SEC = 2.0


class UserError(Exception):
    """Bad input from the command line: printed as one line, exit status 1."""


def run_verb(
    command: str,
    args: argparse.Namespace,
    verb: Callable[[argparse.Namespace], Coroutine[Any, Any, int]],
    *,
    interrupted: int | None = None,
) -> int:
    """Run a graph command's verb (``aiorobot COMMAND VERB ...``) to its exit status.

    A :class:`UserError` is one line on stderr, ``aiorobot COMMAND VERB: error: ...``, and
    status 1. ``interrupted``: the status of Ctrl-C for verbs that run until stopped (``topic
    echo``, ``tf echo``); other verbs let it reach the CLI's own handling (130).
    """
    from .. import run

    try:
        return run(verb(args))
    except UserError as err:
        print(f"aiorobot {command} {args.verb}: error: {err}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        if interrupted is None:
            raise
        return interrupted


def add_graph_options(parser: argparse.ArgumentParser) -> None:
    from .._core._transport import transport_names

    parser.add_argument(
        "--transport", choices=[n for n in transport_names() if n != "local"], default="zenoh",
        help="how to reach the graph: zenoh (rmw_zenoh's, the default) or dds (ROS 2 on DDS: docs/dds.md)",
    )
    parser.add_argument(
        "--connect", action="append", metavar="ENDPOINT",
        help="zenoh endpoint of a router or peer (default tcp/127.0.0.1:7447, as rmw_zenoh)",
    )
    parser.add_argument("--domain-id", type=int, default=None, help="ROS domain id (default: ROS_DOMAIN_ID or 0)")


@asynccontextmanager
async def join_graph(args: argparse.Namespace) -> AsyncIterator[Any]:
    """A runtime on the chosen transport (zenoh unless ``--transport``) that has seen the graph's current
    entities (zenoh's liveliness tokens, DDS's discovery data)."""
    from .. import Runtime
    from .._core._transport import make_transport

    domain = args.domain_id if args.domain_id is not None else int(os.environ.get("ROS_DOMAIN_ID", "0") or 0)
    name = getattr(args, "transport", "zenoh")
    options: dict[str, Any] = {}
    if name == "zenoh":
        options["connect"] = args.connect
    elif args.connect:
        raise UserError(f"--connect: zenoh endpoints, but --transport is {name}; DDS finds its peers itself (docs/dds.md)")
    transport = make_transport(name, domain_id=domain, **options)
    async with Runtime(transport=transport, domain_id=domain, handle_signals=False) as rt:
        await settle_discovery(transport)
        yield rt


async def settle_discovery(transport: Any) -> None:
    def count() -> int:  # remote entities, and nodes (DDS names them apart from its endpoints)
        return len(transport._remote) + len(transport.remote_nodes())

    start = last_change = time.monotonic()
    seen = count()
    while time.monotonic() - start < DISCOVERY_MAX_SEC:
        await asyncio.sleep(0.02)
        now_seen = count()
        if now_seen != seen:
            seen, last_change = now_seen, time.monotonic()
        elif time.monotonic() - last_change >= (QUIET_SEC if seen else EMPTY_QUIET_SEC) and not getattr(transport, "_describing", None):
            return  # quiet, and no remote node is still describing a type this process did not know


def remote_node_names(rt: Any) -> list[str]:
    """Fully qualified names of the graph's nodes, the command's own left out, sorted."""
    own = {n.get_fully_qualified_name() for n in rt.nodes}
    return sorted({n.fully_qualified_name for n in rt.graph.nodes} - own)


def resolve_node(rt: Any, name: str) -> str:
    """``name`` as a fully qualified node name of the graph, or a UserError naming it."""
    fqn = name if name.startswith("/") else "/" + name
    if fqn not in remote_node_names(rt):
        raise UserError(f"unknown node {name!r}; 'aiorobot node list' shows the nodes")
    return fqn


def cli_node(rt: Any, name: str) -> Any:
    """The command's own node (no parameter services of its own), created once per runtime."""
    from .. import Node

    for node in rt.nodes:
        if node.get_name() == name:
            return node
    return rt.add_node(Node(name, start_parameter_services=False))


async def call_service(node: Any, srv_type: Any, name: str, request: Any, timeout_sec: float) -> Any:
    """One call of service ``name``; a UserError when no server answers within ``timeout_sec``."""
    from .. import ServiceError

    client = node.create_client(srv_type, name)
    try:
        if not await client.wait_for_service(timeout_sec=timeout_sec):
            raise UserError(f"no server for {name} [{srv_type.__msgtype__}] within {timeout_sec} s")
        return await client.call(request, timeout_sec=timeout_sec)
    except (ServiceError, TimeoutError) as err:
        raise UserError(f"{name}: {err or 'no response within ' + str(timeout_sec) + ' s'}") from None
    finally:
        node.destroy_client(client)


def to_plain(msg: Any) -> Any:
    """A message as plain Python data (dicts, lists, numbers, strings) in field order."""
    if hasattr(msg, "get_fields_and_field_types"):
        return {name: to_plain(getattr(msg, name)) for name in msg.get_fields_and_field_types()}
    if isinstance(msg, np.ndarray):
        return [to_plain(v) for v in msg.tolist()]
    if isinstance(msg, (list, tuple)):
        return [to_plain(v) for v in msg]
    if isinstance(msg, np.generic):
        return msg.item()
    if isinstance(msg, bytes):
        return list(msg)
    return msg


def message_to_yaml(msg: Any) -> str:
    """ros2cli's echo format: block YAML of the fields, in order."""
    import yaml

    return yaml.safe_dump(to_plain(msg), sort_keys=False, default_flow_style=False, allow_unicode=True)


def fill_message(msg_type: Any, text: str) -> Any:
    """A ``msg_type`` instance from YAML text (``"{linear: {x: 0.5}}"``), naming the field at fault."""
    import yaml

    try:
        data = yaml.safe_load(text) if text.strip() else {}
    except yaml.YAMLError as err:
        raise UserError(f"values: expected YAML such as '{{linear: {{x: 0.5}}}}', found {text!r} ({err})") from None
    if data is None:
        data = {}
    return _fill(msg_type, data, msg_type.__msgtype__)


def _fill(msg_type: Any, data: Any, where: str) -> Any:
    if not isinstance(data, dict):
        raise UserError(f"{where}: expected a mapping of fields for {msg_type.__msgtype__}, found {data!r}")
    fields = msg_type.get_fields_and_field_types()
    msg = msg_type()
    for key, value in data.items():
        if key not in fields:
            raise UserError(
                f"{where}.{key}: {msg_type.__msgtype__} has no field {key!r}; its fields are {', '.join(fields)}"
            )
        current = getattr(msg, key)
        if hasattr(current, "get_fields_and_field_types"):
            value = _fill(type(current), value, f"{where}.{key}")
        elif isinstance(current, list) and isinstance(value, list) and fields[key].startswith(("sequence<", "")) and value and isinstance(value[0], dict):
            from ..msgs import get

            inner = fields[key].split("<", 1)[-1].rstrip(">").split(",")[0].strip()
            try:
                cls = get(inner)
                value = [_fill(cls, v, f"{where}.{key}[{i}]") for i, v in enumerate(value)]
            except UserError:
                raise
            except Exception:
                pass
        try:
            setattr(msg, key, value)
        except (TypeError, ValueError) as err:
            raise UserError(f"{where}.{key}: expected {fields[key]}, found {value!r} ({err})") from None
    from ..msgs import SerializationError, serialize

    try:
        serialize(msg)
    except SerializationError as err:
        raise UserError(f"{where}: {err}") from None
    return msg
