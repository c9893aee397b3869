"""ROS 2 YAML parameter files: ``node_name:`` / ``/**:`` sections with ``ros__parameters``.

The format of ``ros2 run ... --ros-args --params-file f.yaml`` and launch files::

    /**:                        # every node
      ros__parameters:
        use_sim_time: true
    /robot1/controller:         # one node by its fully qualified name
      ros__parameters:
        pid: {kp: 1.0, ki: 0.1} # nested tables flatten to pid.kp, pid.ki
    robot2:                     # nesting spells the namespace too
      "*":                      # * is one name, ** any number of them
        ros__parameters: {rate_hz: 20}

Sections apply in file order and a later match overrides an earlier one, as rcl
(rclpy test_node.py::test_node_ns_params_file_by_order). Repeated keys are kept,
which plain YAML loading would silently drop.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ._rcl_yaml import NoValue, Pairs, homogeneous, load_yaml

__all__ = ["ParameterFile", "ParameterFileError", "load_parameter_file", "parameter_dict_from_yaml_file"]

PARAMS_KEY = "ros__parameters"


class ParameterFileError(ValueError):
    """A parameter file that is not valid YAML or not in the ROS 2 layout; the message names
    the file and the key."""

    def __init__(self, path: str, key: str | None, message: str) -> None:
        self.path = path
        self.key = key
        super().__init__(f"{path}: {key}: {message}" if key else f"{path}: {message}")


@dataclass(frozen=True, slots=True)
class _Section:
    pattern: str  # as written, normalised: "/ns/*"
    regex: re.Pattern[str]
    parameters: Mapping[str, Any]
    #: where each value was written: ``"params.yaml: node.ros__parameters.name (line 7)"``
    sources: Mapping[str, str]


def _node_regex(pattern: str) -> re.Pattern[str]:
    parts = []
    for token in (t for t in pattern.split("/") if t):
        if token == "**":
            parts.append(r"(?:/[^/]+)*")
        elif token == "*":
            parts.append(r"/[^/]+")
        else:
            parts.append("/" + re.escape(token).replace(r"\*", "[^/]*"))
    return re.compile("".join(parts) or "/")


class ParameterFile:
    """A loaded parameter file: ``for_node("/ns/name")`` gives the values that apply to a node."""

    def __init__(self, path: str, sections: list[_Section]) -> None:
        self.path = path
        self.sections = sections

    def __repr__(self) -> str:
        return f"<ParameterFile {self.path} sections={[s.pattern for s in self.sections]}>"

    def for_node(self, fqn: str) -> dict[str, Any]:
        """Flattened ``{name: value}`` for the node ``fqn``: matching sections, later ones winning."""
        out: dict[str, Any] = {}
        for section in self.sections:
            if section.regex.fullmatch(fqn):
                out.update(section.parameters)
        return out

    def sources_for_node(self, fqn: str) -> dict[str, str]:
        """``{name: "file: key (line N)"}`` for the values :meth:`for_node` gives."""
        out: dict[str, str] = {}
        for section in self.sections:
            if section.regex.fullmatch(fqn):
                out.update(section.sources)
        return out


def load_parameter_file(path: str | Path) -> ParameterFile:
    """Read a ROS 2 parameter file with rcl's scalar types (``1e-9`` is a double; see
    :mod:`aiorobot._core._rcl_yaml`); ``FileNotFoundError`` when missing, ``ParameterFileError``
    when malformed.

    rclpy difference: a list mixing integers and doubles is a double array (rcl refuses it).
    """
    import yaml

    text = Path(path).read_text(encoding="utf-8")
    name = str(path)
    try:
        data = load_yaml(text)
    except yaml.YAMLError as err:
        mark = getattr(err, "problem_mark", None)
        where = f" at line {mark.line + 1}" if mark is not None else ""
        raise ParameterFileError(name, None, f"not valid YAML{where}: {getattr(err, 'problem', err)}") from None
    if data is None:
        return ParameterFile(name, [])
    if not isinstance(data, Pairs):
        raise ParameterFileError(name, None, f"expected a mapping of node names to sections, found {type(data).__name__}")
    sections: list[_Section] = []
    _walk(name, data, [], sections)
    return ParameterFile(name, sections)


def _walk(path: str, table: Pairs, keys: list[str], out: list[_Section]) -> None:
    for key, value, line in table:
        if key == PARAMS_KEY:
            if not keys:
                expected = f"expected a node name (or /**) above ros__parameters (line {line})"
                raise ParameterFileError(path, key, expected)
            pattern = "/" + "/".join(t for k in keys for t in k.split("/") if t)
            where = f"{pattern}.{PARAMS_KEY}"
            if not isinstance(value, Pairs):
                found = f"expected a mapping of parameters, found {_found(value)} (line {line})"
                raise ParameterFileError(path, where, found)
            flat: dict[str, Any] = {}
            sources: dict[str, str] = {}
            _flatten(path, value, "", where, flat, sources)
            out.append(_Section(pattern, _node_regex(pattern), flat, sources))
        elif isinstance(value, Pairs):
            _walk(path, value, keys + [key], out)
        else:
            where = "/".join(keys + [key])
            raise ParameterFileError(
                path, where, f"expected a node section holding ros__parameters, found {_found(value)} (line {line})"
            )


def _found(value: Any) -> str:
    if isinstance(value, NoValue):
        return "no value"
    if isinstance(value, Pairs):
        return "a mapping"
    return repr(value)


def _flatten(path: str, table: Pairs, prefix: str, where: str, out: dict[str, Any], sources: dict[str, str]) -> None:
    for key, value, line in table:
        name = f"{prefix}{key}"
        key_path = f"{where}.{name}"
        if isinstance(value, Pairs):
            _flatten(path, value, f"{name}.", where, out, sources)
            continue
        if isinstance(value, NoValue):
            raise ParameterFileError(path, key_path, f"expected a value, found none (line {line})")
        if isinstance(value, list):
            if any(isinstance(v, (Pairs, list, NoValue)) for v in value):
                found = f"expected a flat list of values, found {value!r} (line {line})"
                raise ParameterFileError(path, key_path, found)
            try:
                value = homogeneous(value, "the list")
            except ValueError as err:
                raise ParameterFileError(path, key_path, f"{err} (line {line})") from None
        out[name] = value
        sources[name] = f"{path}: {key_path} (line {line})"


def parameter_dict_from_yaml_file(
    parameter_file: str | Path,
    use_wildcard: bool = False,
    target_nodes: list[str] | None = None,
    namespace: str = "",
) -> dict[str, Any]:
    """rclpy's function: ``{name: rcl_interfaces/msg/Parameter}`` from a parameter file.

    Loads every node's section when ``target_nodes`` is empty (``/**`` only with
    ``use_wildcard``); ``RuntimeError`` when a target node is not in the file.
    """
    from ._parameter_types import Parameter

    loaded = load_parameter_file(parameter_file)
    patterns = [s.pattern for s in loaded.sections]
    wanted: list[str] = []
    if use_wildcard and "/**" in patterns:
        wanted.append("/**")
    for node in target_nodes or []:
        fqn = node if node.startswith("/") else "/" + node
        if fqn not in patterns:
            raise RuntimeError(f"param file does not contain parameters for {node}, only for nodes: {patterns}")
        wanted.append(fqn)
    out: dict[str, Any] = {}
    for section in loaded.sections:
        if (not target_nodes and (section.pattern != "/**" or use_wildcard)) or section.pattern in wanted:
            for name, value in section.parameters.items():
                full = f"{namespace}{name}"
                out[full] = Parameter(full, value=value).to_parameter_msg()
    return out
