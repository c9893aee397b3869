"""``aiorobot interface list|packages|package|show``: ros2 interface over ``aiorobot.msgs`` (offline).

The types are the ones this installation knows (the Jazzy snapshot and the shipped
.msg/.srv/.action files); no graph is joined. ``show`` prints a definition as rosidl
text with nested types expanded beneath their field, one tab deeper, as ros2 interface
show does; the snapshot keeps no comments, so none are printed.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from typing import Any

from ._graph_session import UserError

__all__ = ["add_arguments", "main"]

_KINDS = (("msg", "Messages"), ("srv", "Services"), ("action", "Actions"))


def add_arguments(parser: argparse.ArgumentParser) -> None:
    verbs = parser.add_subparsers(dest="verb", metavar="VERB", required=True)
    p = verbs.add_parser("list", help="every interface type")
    _add_only_flags(p)
    verbs.add_parser("packages", help="packages holding interface types")
    p = verbs.add_parser("package", help="the interface types of one package")
    _add_only_flags(p)
    p.add_argument("package_name")
    p = verbs.add_parser("show", help="an interface's definition, nested types expanded")
    p.add_argument("type", help="e.g. geometry_msgs/msg/Twist, std_srvs/srv/Trigger")


def _add_only_flags(p: argparse.ArgumentParser) -> None:
    p.add_argument("-m", "--only-msgs", action="store_true", help="only message types")
    p.add_argument("-s", "--only-srvs", action="store_true", help="only service types")
    p.add_argument("-a", "--only-actions", action="store_true", help="only action types")


def main(args: argparse.Namespace) -> int:
    try:
        return _main(args)
    except UserError as err:
        print(f"aiorobot interface {args.verb}: error: {err}", file=sys.stderr)
        return 1
    except BrokenPipeError:  # `aiorobot interface list | head`: the reader left; not an error
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0


def _main(args: argparse.Namespace) -> int:
    from ..msgs._registry import all_names

    names = all_names()
    if args.verb == "show":
        print(show_text(args.type), end="")
        return 0
    if args.verb == "packages":
        print("\n".join(sorted({n.split("/", 1)[0] for n in names})))
        return 0
    kinds = [k for k, flag in (("msg", args.only_msgs), ("srv", args.only_srvs), ("action", args.only_actions)) if flag]
    kinds = kinds or ["msg", "srv", "action"]
    if args.verb == "package":
        in_package = [n for n in names if n.split("/", 1)[0] == args.package_name]
        if not in_package:
            packages = sorted({n.split("/", 1)[0] for n in names})
            raise UserError(f"unknown package {args.package_name!r}; "
                            f"'aiorobot interface packages' lists the {len(packages)} known packages")
        for name in in_package:
            if name.split("/")[1] in kinds:
                print(name)
        return 0
    for kind, title in _KINDS:
        if kind in kinds:
            print(f"{title}:")
            for name in names:
                if name.split("/")[1] == kind:
                    print(f"    {name}")
    return 0


def show_text(name: str) -> str:
    """``name``'s definition: request/response (or goal/result/feedback) sections split by ``---``."""
    from ..msgs._registry import ActionSpec, ServiceSpec, get_spec

    if name.count("/") != 2:
        raise UserError(f"type: expected pkg/msg/Name, pkg/srv/Name or pkg/action/Name, found {name!r}")
    try:
        spec = get_spec(name)
    except LookupError as err:
        raise UserError(str(err).strip("'\"")) from None
    if isinstance(spec, ServiceSpec):
        sections = [spec.request, spec.response]
    elif isinstance(spec, ActionSpec):
        sections = [spec.goal, spec.result, spec.feedback]
    else:
        sections = [spec]
    package = spec.name.split("/", 1)[0]
    lines: list[str] = []
    for i, section in enumerate(sections):
        if i:
            lines.append("---")
        _append(lines, section, package, 0)
    return "\n".join(lines) + "\n"


def _append(lines: list[str], spec: Any, package: str, depth: int) -> None:
    from ..msgs._describe import _type_text
    from ..msgs._registry import get_spec

    indent = "\t" * depth
    for c in spec.constants:
        lines.append(f"{indent}{c.type} {c.name}={c.value}")
    for f in spec.fields:
        if f.name == "structure_needs_at_least_one_member":
            continue
        default = "" if f.default is None else " " + _literal(f.default)
        lines.append(f"{indent}{_type_text(f.type, package)} {f.name}{default}")
        if f.type.is_message:
            nested = get_spec(f.type.base)
            _append(lines, nested, f.type.base.split("/", 1)[0], depth + 1)


def _literal(value: Any) -> str:
    """A default value as rosidl writes it: ``true``, ``1.5``, ``"text"``, ``[1, 2]``."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return json.dumps(value)
    if isinstance(value, (list, tuple)) or hasattr(value, "tolist"):
        items = value.tolist() if hasattr(value, "tolist") else value
        return "[" + ", ".join(_literal(v) for v in items) + "]"
    return str(value)
