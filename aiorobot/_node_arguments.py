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


def resolve_node_arguments(
    name: str,
    namespace: str,
    parameter_overrides: Mapping[str, Any] | Iterable[Any] | None,
    remappings: dict[str, str],
    cli_args: Sequence[str] | None,
) -> NodeArguments:
    """Precedence, lowest first: parameter files in order, ``-p`` values, ``parameter_overrides``
    (a mapping or rclpy's list of ``Parameter``); ``-r`` rules, then ``remappings``."""
    overrides = _overrides_dict(parameter_overrides)
    if cli_args is None:
        return NodeArguments(overrides, remappings)
    if isinstance(cli_args, str) or not all(isinstance(a, str) for a in cli_args):
        raise TypeError(f"cli_args: expected a list of str, found {cli_args!r}")
    from .parameters._files import load_parameter_file
    from ._ros_args import parse_ros_args

    args = parse_ros_args(list(cli_args))
    remaps = {**args.remappings_for(name), **remappings}
    final_name = validate_node_name(remaps.get("__node", remaps.get("__name", name)))
    if "__name" in remaps:
        remaps.setdefault("__node", remaps.pop("__name"))
    fqn = join_fqn(validate_namespace(remaps.get("__ns", namespace)), final_name)
    merged: dict[str, Any] = {}
    for path in args.params_files:
        merged.update(load_parameter_file(path).for_node(fqn))
    merged.update(args.parameters_for(name))
    quiet = set(merged) - set(overrides)
    merged.update(overrides)
    level = args.log_levels.get(final_name, args.log_levels.get(fqn, args.log_level))  # --log-level name:=level
    return NodeArguments(merged, remaps, quiet, level)


def _overrides_dict(overrides: Mapping[str, Any] | Iterable[Any] | None) -> dict[str, Any]:
    """Overrides as ``{name: value}``: a mapping, or rclpy's list of ``Parameter``."""
    if overrides is None:
        return {}
    if isinstance(overrides, Mapping):
        return dict(overrides)
    from ._parameters import Parameter

    out = {}
    for p in overrides:
        if not isinstance(p, Parameter):
            raise TypeError(f"parameter_overrides: expected a mapping or a list of Parameter, found {p!r}")
        out[p.name] = p.value
    return out
