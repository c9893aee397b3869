"""The ``--ros-args`` command-line grammar of ROS 2 (rcl's ``rcl_parse_arguments``), as a pure parser.

``prog a b --ros-args -p rate:=5.0 -r /scan:=/base/scan --params-file f.yaml -- c``:
ROS arguments sit between ``--ros-args`` and ``--`` (or the end; there may be several
such sections); the rest are the program's own arguments. Understood:

- ``-p``/``--param [node:]name:=value`` (value typed as rcl types YAML: ``1e-9`` is a double),
- ``-r``/``--remap [node:]from:=to``, including ``__node:=name`` and ``__ns:=/ns``,
- ``--params-file FILE``,
- ``--log-level [logger:=]LEVEL``,
- ``--enable-rosout-logs`` / ``--disable-rosout-logs`` (the nodes' ``/rosout``, as rcl),
- ``--enclave``/``-e VALUE``, ``--disable-stdout-logs`` and the like (accepted, no effect here).

A ``node:`` prefix makes a rule apply only to the node of that name. ``-p`` values and
``--params-file`` sections apply in command-line order, as rcl reads them into one table
(:func:`aiorobot._core._node_arguments.resolve_node_arguments`).
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from typing import Any

__all__ = ["RosArgs", "RosArgsError", "Rule", "parse_ros_args", "strip_ros_args"]

LOG_LEVELS = ("debug", "info", "warn", "warning", "error", "fatal")
_FLAGS_WITHOUT_VALUE = (
    "--enable-rosout-logs",
    "--disable-rosout-logs",
    "--enable-stdout-logs",
    "--disable-stdout-logs",
    "--enable-external-lib-logs",
    "--disable-external-lib-logs",
)
_FLAGS_WITH_VALUE = ("-e", "--enclave", "--log-config-file", "--log-file-name")


class RosArgsError(ValueError):
    """A malformed ``--ros-args`` section; the message quotes the argument and the expected form."""


@dataclass(frozen=True, slots=True)
class Rule:
    """A ``-p`` or ``-r`` rule, for every node (``node`` is None) or the node so named."""

    node: str | None
    key: str
    value: Any


@dataclass(slots=True)
class RosArgs:
    """What ``parse_ros_args`` found."""

    parameters: list[Rule] = field(default_factory=list)
    remappings: list[Rule] = field(default_factory=list)
    params_files: list[str] = field(default_factory=list)
    log_levels: dict[str, str] = field(default_factory=dict)  # "" = the default level
    unparsed: list[str] = field(default_factory=list)
    #: ``--enable-rosout-logs`` (True) / ``--disable-rosout-logs`` (False), the last one given
    rosout: bool | None = None
    #: ``-p`` rules and ``--params-file`` paths in command-line order
    overrides_in_order: list[Rule | str] = field(default_factory=list)

    def parameters_for(self, node_name: str) -> dict[str, Any]:
        """The ``-p`` values that apply to the node called ``node_name``; node-targeted ones win."""
        out = {r.key: r.value for r in self.parameters if r.node is None}
        out.update({r.key: r.value for r in self.parameters if r.node == node_name})
        return out

    def remappings_for(self, node_name: str) -> dict[str, str]:
        """The ``-r`` rules for the node called ``node_name`` (``__node``/``__ns`` included)."""
        out = {r.key: str(r.value) for r in self.remappings if r.node is None}
        out.update({r.key: str(r.value) for r in self.remappings if r.node == node_name})
        return out

    @property
    def log_level(self) -> str | None:
        return self.log_levels.get("")


def parse_ros_args(argv: Sequence[str]) -> RosArgs:
    """Split ``argv`` into ROS arguments (parsed) and the program's own (``unparsed``)."""
    from ._rcl_yaml import parse_yaml_value

    result = RosArgs()
    args = list(argv)
    i = 0
    in_ros = False
    while i < len(args):
        arg = args[i]
        if arg == "--ros-args":
            in_ros = True
            i += 1
            continue
        if not in_ros:
            result.unparsed.append(arg)
            i += 1
            continue
        if arg == "--":
            in_ros = False
            i += 1
            continue
        if arg in _FLAGS_WITHOUT_VALUE:
            if arg.endswith("-rosout-logs"):
                result.rosout = arg == "--enable-rosout-logs"
            i += 1
            continue
        if arg not in ("-p", "--param", "-r", "--remap", "--params-file", "--log-level", *_FLAGS_WITH_VALUE):
            raise RosArgsError(
                f"unknown ROS argument {arg!r} after --ros-args; expected -p name:=value, -r from:=to, "
                "--params-file FILE or --log-level LEVEL (end ROS arguments with --)"
            )
        value = _value_of(args, i)
        if arg in ("-p", "--param"):
            node, name, text = _rule(arg, value, "name:=value")
            try:
                rule = Rule(node, name, parse_yaml_value(text))
            except ValueError as err:
                raise RosArgsError(f"{arg} {value}: {err}") from None
            result.parameters.append(rule)
            result.overrides_in_order.append(rule)
        elif arg in ("-r", "--remap"):
            node, source, target = _rule(arg, value, "from:=to")
            result.remappings.append(Rule(node, source, target))
        elif arg == "--params-file":
            result.params_files.append(value)
            result.overrides_in_order.append(value)
        elif arg == "--log-level":
            logger, sep, level = value.rpartition(":=")
            if level.lower() not in LOG_LEVELS:
                raise RosArgsError(
                    f"--log-level: expected a level ({', '.join(LOG_LEVELS)}) or logger:=level, found {value!r}"
                )
            result.log_levels[logger if sep else ""] = "warning" if level.lower() == "warn" else level.lower()
        i += 2
    return result


def _value_of(args: list[str], i: int) -> str:
    if i + 1 >= len(args) or args[i + 1] in ("--", "--ros-args"):
        found = "nothing" if i + 1 >= len(args) else repr(args[i + 1])
        raise RosArgsError(f"{args[i]}: expected a value after it, found {found}")
    return args[i + 1]


def _rule(flag: str, text: str, form: str) -> tuple[str | None, str, str]:
    left, sep, right = text.partition(":=")
    if not sep or not left:
        raise RosArgsError(f"{flag}: expected [node:]{form}, found {text!r}")
    node, colon, key = left.rpartition(":")
    if colon and not node:
        raise RosArgsError(f"{flag}: expected node:{form} with a node name before ':', found {text!r}")
    return (node or None), key, right


def strip_ros_args(argv: Iterable[str]) -> list[str]:
    """``argv`` without its ROS arguments (rclpy's ``remove_ros_args``)."""
    return parse_ros_args(list(argv)).unparsed
