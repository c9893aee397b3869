"""``aiorobot param list|get|set|dump|load|describe``: ros2 param against a running graph (zenoh).

Every verb talks to the node's ``rcl_interfaces`` parameter services (``~/list_parameters``
and the rest), so it reaches aiorobot and ROS 2 nodes alike. Output is ros2param's.
"""

from __future__ import annotations

import argparse
import asyncio
import os
import re
import sys
from typing import Any

from ._graph_session import (
    UserError,
    add_graph_options,
    call_service,
    cli_node,
    join_graph,
    remote_node_names,
    resolve_node,
    run_verb,
)

__all__ = ["add_arguments", "main"]

#: ros2param's names of ``rcl_interfaces/msg/ParameterType`` values
TYPE_NAMES = {
    0: "not set",
    1: "boolean",
    2: "integer",
    3: "double",
    4: "string",
    5: "byte array",
    6: "boolean array",
    7: "integer array",
    8: "double array",
    9: "string array",
}

#: ros2 param get's label per type
_GET_LABELS = {
    1: "Boolean value is:",
    2: "Integer value is:",
    3: "Double value is:",
    4: "String value is:",
    5: "Byte values are:",
    6: "Boolean values are:",
    7: "Integer values are:",
    8: "Double values are:",
    9: "String values are:",
}


def add_arguments(parser: argparse.ArgumentParser) -> None:
    verbs = parser.add_subparsers(dest="verb", metavar="VERB", required=True)
    p = verbs.add_parser("list", help="parameters of one node, or of every node")
    p.add_argument("node_name", nargs="?")
    p.add_argument("--filter", help="only names matching this regular expression")
    p.add_argument("--param-prefixes", nargs="+", default=[], help="only names with these prefixes")
    p.add_argument("--param-type", action="store_true", help="print each parameter's type")
    p = verbs.add_parser("get", help="a parameter's value")
    p.add_argument("node_name")
    p.add_argument("parameter_name")
    p.add_argument("--hide-type", action="store_true", help="print the value only")
    p = verbs.add_parser("set", help="set a parameter; the value is read as YAML (true, 3, 2.5, [1, 2], text)")
    p.add_argument("node_name")
    p.add_argument("parameter_name")
    p.add_argument("value")
    p = verbs.add_parser("dump", help="a node's parameters as a ROS 2 parameter file")
    p.add_argument("node_name")
    p.add_argument("--output-dir", metavar="DIR", help="write DIR/<node>.yaml instead of printing")
    p = verbs.add_parser("load", help="set a node's parameters from a ROS 2 parameter file")
    p.add_argument("node_name")
    p.add_argument("parameter_file")
    p.add_argument("--no-use-wildcard", action="store_true", help="leave out the file's '/**' section")
    p = verbs.add_parser("describe", help="parameters' types, descriptions and constraints")
    p.add_argument("node_name")
    p.add_argument("parameter_names", nargs="+")
    for sub in verbs.choices.values():
        sub.add_argument("--timeout", type=float, default=5.0, help="seconds to wait for the node's services")
        add_graph_options(sub)


def main(args: argparse.Namespace) -> int:
    return run_verb("param", args, _main)


async def _main(args: argparse.Namespace) -> int:
    regex = None
    if args.verb == "list" and args.filter is not None:
        try:
            regex = re.compile(args.filter)
        except re.error as err:
            raise UserError(f"--filter: expected a regular expression, found {args.filter!r} ({err})") from None
    if args.verb == "load":
        parameters = _read_file_for_check(args.parameter_file)  # a bad file starts nothing
    if args.verb == "dump" and args.output_dir is not None and not os.path.isdir(args.output_dir):
        raise UserError(f"--output-dir: expected a directory, found {args.output_dir!r}")
    async with join_graph(args) as rt:
        node = cli_node(rt, "aiorobot_param")
        if args.verb == "list":
            return await _list(rt, node, args, regex)
        fqn = resolve_node(rt, args.node_name)
        if args.verb == "get":
            return await _get(node, fqn, args)
        if args.verb == "set":
            return await _set(node, fqn, args)
        if args.verb == "dump":
            return await _dump(node, fqn, args)
        if args.verb == "load":
            return await _load(node, fqn, args, parameters)
        return await _describe(node, fqn, args)


async def _call(node: Any, fqn: str, service: str, timeout_sec: float, **request: Any) -> Any:
    from ..msgs import rcl_interfaces as ri

    srv_type = getattr(ri, "".join(w.capitalize() for w in service.split("_")))
    return await call_service(node, srv_type, f"{fqn}/{service}", srv_type.Request(**request), timeout_sec)


async def _list(rt: Any, node: Any, args: argparse.Namespace, regex: re.Pattern[str] | None) -> int:
    if args.node_name:
        nodes = [resolve_node(rt, args.node_name)]
    else:  # nodes without parameter services (start_parameter_services=False) are left out
        services = {s.name for s in rt.graph.services}
        nodes = [n for n in remote_node_names(rt) if f"{n}/list_parameters" in services]
    responses = await asyncio.gather(
        *(_call(node, n, "list_parameters", args.timeout, prefixes=args.param_prefixes, depth=0) for n in nodes),
        return_exceptions=len(nodes) > 1,  # listing every node: one that does not answer is reported, not fatal
    )
    for fqn, response in zip(nodes, responses):
        if isinstance(response, UserError):
            print(f"aiorobot param list: {fqn}: {response}", file=sys.stderr)
            continue
        if isinstance(response, BaseException):
            raise response
        names = sorted(response.result.names)
        if regex is not None:
            names = [n for n in names if regex.match(n)]
        if not args.node_name and names:
            print(f"{fqn}:")
        types: dict[str, str] = {}
        if args.param_type and names:
            described = await _call(node, fqn, "describe_parameters", args.timeout, names=names)
            types = {d.name: TYPE_NAMES.get(int(d.type), str(d.type)) for d in described.descriptors}
        for name in names:
            print(f"  {name} (type: {types.get(name, 'not set')})" if args.param_type else f"  {name}")
    return 0


async def _get(node: Any, fqn: str, args: argparse.Namespace) -> int:
    from .._core._parameter_types import parameter_value_to_python

    response = await _call(node, fqn, "get_parameters", args.timeout, names=[args.parameter_name])
    if not response.values:
        raise UserError(f"parameter {args.parameter_name!r} is not declared on {fqn}; "
                        f"'aiorobot param list {fqn}' shows its parameters")
    value = response.values[0]
    if int(value.type) == 0:
        print("Parameter not set.")
        return 0
    python = _plain_value(parameter_value_to_python(value))
    print(python if args.hide_type else f"{_GET_LABELS[int(value.type)]} {python}")
    return 0


async def _set(node: Any, fqn: str, args: argparse.Namespace) -> int:
    from .._core._parameter_types import get_parameter_value
    from ..msgs.rcl_interfaces import Parameter

    value = get_parameter_value(args.value)
    response = await _call(
        node, fqn, "set_parameters", args.timeout, parameters=[Parameter(name=args.parameter_name, value=value)]
    )
    result = response.results[0]
    if not result.successful:
        raise UserError(f"setting {args.parameter_name} on {fqn} to {args.value!r} failed: {result.reason}")
    print("Set parameter successful" + (f": {result.reason}" if result.reason else ""))
    return 0


async def _dump(node: Any, fqn: str, args: argparse.Namespace) -> int:
    import yaml

    from .._core._parameter_types import parameter_value_to_python

    listed = await _call(node, fqn, "list_parameters", args.timeout, prefixes=[], depth=0)
    names = sorted(listed.result.names)
    got = await _call(node, fqn, "get_parameters", args.timeout, names=names)
    params: dict[str, Any] = {}
    for name, value in zip(names, got.values):
        _insert(params, name, _plain_value(parameter_value_to_python(value)))
    text = yaml.dump({fqn: {"ros__parameters": params}}, default_flow_style=False)
    if args.output_dir is None:
        print(text)
        return 0
    path = os.path.join(args.output_dir, fqn[1:].replace("/", "__") + ".yaml")
    print("Saving to: ", path)
    with open(path, "w", encoding="utf-8") as f:
        f.write(text)
    return 0


def _insert(table: dict[str, Any], name: str, value: Any) -> None:
    """ros2param's nesting: ``a.b.c`` becomes ``{a: {b: {c: value}}}``."""
    head, _, rest = name.partition(".")
    if rest:
        _insert(table.setdefault(head, {}), rest, value)
    else:
        table[name] = value


def _plain_value(value: Any) -> Any:
    """Byte arrays as lists of ints, so dumps load back; everything else unchanged."""
    if isinstance(value, list) and value and isinstance(value[0], bytes):
        return [b[0] for b in value]
    return value


def _read_file_for_check(path: str) -> Any:
    from ..parameters import ParameterFileError, load_parameter_file

    try:
        return load_parameter_file(path)
    except FileNotFoundError:
        raise UserError(f"parameter_file: expected a ROS 2 parameter file, found no file {path!r}") from None
    except (ParameterFileError, OSError, UnicodeDecodeError) as err:
        raise UserError(str(err)) from None


async def _load(node: Any, fqn: str, args: argparse.Namespace, loaded: Any) -> int:
    from .._core._parameter_types import Parameter

    values: dict[str, Any] = {}
    for section in loaded.sections:  # later sections win, as when a node starts with the file
        if args.no_use_wildcard and section.pattern == "/**":
            continue
        if section.regex.fullmatch(fqn):
            values.update(section.parameters)
    if not values:
        patterns = ", ".join(s.pattern for s in loaded.sections) or "none"
        raise UserError(f"{args.parameter_file}: no parameters for {fqn} (its sections: {patterns})")
    msgs = [Parameter(name, value=value).to_parameter_msg() for name, value in values.items()]
    response = await _call(node, fqn, "set_parameters", args.timeout, parameters=msgs)
    failed = 0
    for name, result in zip(values, response.results):
        reason = f": {result.reason}" if result.reason else ""
        if result.successful:
            print(f"Set parameter {name} successful{reason}")
        else:
            failed += 1
            print(f"Set parameter {name} failed{reason}", file=sys.stderr)
    return 1 if failed else 0


async def _describe(node: Any, fqn: str, args: argparse.Namespace) -> int:
    response = await _call(node, fqn, "describe_parameters", args.timeout, names=args.parameter_names)
    if not response.descriptors:
        listed = await _call(node, fqn, "list_parameters", args.timeout, prefixes=[], depth=0)
        unknown = [n for n in args.parameter_names if n not in set(listed.result.names)] or args.parameter_names
        raise UserError(f"parameter {', '.join(map(repr, unknown))} is not declared on {fqn}; "
                        f"'aiorobot param list {fqn}' shows its parameters")
    for d in response.descriptors:
        print("Parameter name:", d.name)
        print("  Type:", TYPE_NAMES.get(int(d.type), str(d.type)))
        if d.description:
            print("  Description:", d.description)
        print("  Constraints:")
        if d.read_only:
            print("    Read only: true")
        ranges = list(d.floating_point_range) + list(d.integer_range)
        if ranges:
            print("    Min value:", ranges[0].from_value)
            print("    Max value:", ranges[0].to_value)
            if ranges[0].step:
                print("    Step:", ranges[0].step)
        if d.additional_constraints:
            print("    Additional constraints:", d.additional_constraints)
    return 0
