"""What a node takes from ``cli_args`` (rclpy's ``Node(cli_args=[...])``): remappings, ``-p``
values and ``--params-file`` sections matched to the node's fully qualified name."""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

from ._names import join_fqn, validate_namespace, validate_node_name

__all__ = ["NodeArguments", "resolve_node_arguments"]


@dataclass(slots=True)
class NodeArguments:
    """The merged overrides and remappings of one node, and which overrides came from
    files or ``-p`` (those may name parameters the node never declares, as in ROS 2)."""

    overrides: dict[str, Any]
    remappings: dict[str, str]
    quiet: set[str] = field(default_factory=set)
    log_level: str | None = None
    #: where each file or ``-p`` value came from, for errors: ``"f.yaml: node.ros__parameters.x (line 3)"``
    sources: dict[str, str] = field(default_factory=dict)
    #: ``--enable-rosout-logs`` / ``--disable-rosout-logs``; None when neither is given
    rosout: bool | None = None


def resolve_node_arguments(
    name: str,
    namespace: str,
    parameter_overrides: Mapping[str, Any] | Iterable[Any] | None,
    remappings: dict[str, str],
    cli_args: Sequence[str] | None,
) -> NodeArguments:
    """Precedence, lowest first: ``-p`` values and parameter files in command-line order (as rcl,
    see :func:`_cli_overrides`), then ``parameter_overrides`` (a mapping or rclpy's list of
    ``Parameter``); ``-r`` rules, then ``remappings``."""
    overrides = _overrides_dict(parameter_overrides)
    if cli_args is None:
        return NodeArguments(overrides, remappings)
    if isinstance(cli_args, str) or not all(isinstance(a, str) for a in cli_args):
        raise TypeError(f"cli_args: expected a list of str, found {cli_args!r}")
    from ._ros_args import parse_ros_args

    args = parse_ros_args(list(cli_args))
    remaps = {**args.remappings_for(name), **remappings}
    final_name = validate_node_name(remaps.get("__node", remaps.get("__name", name)))
    if "__name" in remaps:
        remaps.setdefault("__node", remaps.pop("__name"))
    fqn = join_fqn(validate_namespace(remaps.get("__ns", namespace)), final_name)
    merged, sources = _cli_overrides(args, fqn)
    quiet = set(merged) - set(overrides)
    merged.update(overrides)
    for overridden in overrides:
        sources.pop(overridden, None)
    level = args.log_levels.get(final_name, args.log_levels.get(fqn, args.log_level))  # --log-level name:=level
    return NodeArguments(merged, remaps, quiet, level, sources, args.rosout)


def _cli_overrides(args: Any, fqn: str) -> tuple[dict[str, Any], dict[str, str]]:
    """The ``-p`` and ``--params-file`` values for the node ``fqn``, and where each came from.

    As rcl (``rcl_parse_arguments``) and rclpy (``Node.get_parameters``): both go, in
    command-line order, into one table of node sections (``-p name:=v`` into ``/**``,
    ``-p node:name:=v`` into ``/node``, a file's sections under their names), a later value
    replacing an earlier one in its section; then the sections matching the node apply in the
    order each first appeared. So ``-p x:=1 --params-file f.yaml`` gives the file's ``x``
    (rclpy test_node.py::TestNode::test_declare_parameter).
    """
    from ._parameter_files import _node_regex, load_parameter_file

    sections: dict[str, tuple[Any, dict[str, tuple[Any, str]]]] = {}
    for item in args.overrides_in_order:
        if isinstance(item, str):
            for section in load_parameter_file(item).sections:
                table = sections.setdefault(section.pattern, (section.regex, {}))[1]
                for key, value in section.parameters.items():
                    table[key] = (value, section.sources[key])
        else:
            pattern = "/**" if item.node is None else "/" + item.node
            table = sections.setdefault(pattern, (_node_regex(pattern), {}))[1]
            prefix = f"{item.node}:" if item.node is not None else ""
            table[item.key] = (item.value, f"--ros-args -p {prefix}{item.key}")
    values: dict[str, Any] = {}
    sources: dict[str, str] = {}
    for regex, table in sections.values():
        if regex.fullmatch(fqn):
            for key, (value, source) in table.items():
                values[key] = value
                sources[key] = source
    return values, sources


def _overrides_dict(overrides: Mapping[str, Any] | Iterable[Any] | None) -> dict[str, Any]:
    """Overrides as ``{name: value}``: a mapping, or rclpy's list of ``Parameter``."""
    if overrides is None:
        return {}
    if isinstance(overrides, Mapping):
        return dict(overrides)
    from ._parameter_types import Parameter

    out = {}
    for p in overrides:
        if not isinstance(p, Parameter):
            raise TypeError(f"parameter_overrides: expected a mapping or a list of Parameter, found {p!r}")
        out[p.name] = p.value
    return out
