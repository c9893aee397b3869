"""The graph configuration read by ``aiorobot run``: a TOML file parsed into frozen dataclasses.

This module is the pure half of the loader: :func:`load_config` reads and validates a
file and never imports user code or builds a node. :func:`aiorobot.launch.build_nodes`
is the other half (imports the node classes and constructs the nodes).

Every problem raises :class:`ConfigError` naming the file, the key path (``nodes[1].executor``)
and what was expected against what was found, on one line::

    bad.toml: nodes[1].executor: expected "main" or "priority", found "fast"
"""

from __future__ import annotations

import datetime
import difflib
import json
import math
import re
import tomllib
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import Any

from .._core._errors import ConfigError, InvalidNameError
from .._core._names import expand_name, validate_namespace, validate_node_name
from .._core._runtime import (
    EXECUTORS,
    LATE_THRESHOLD_SEC,
    PRIORITY_STALL_THRESHOLD_SEC,
    SHUTDOWN_TIMEOUT_SEC,
    STALL_THRESHOLD_SEC,
)
from .._core._transport import MAX_DOMAIN_ID, transport_names

__all__ = [
    "EXECUTORS",
    "FoxgloveConfig",
    "LOG_LEVELS",
    "MAIN_PROCESS",
    "ConfigError",
    "GraphConfig",
    "NodeConfig",
    "ProcessConfig",
    "RESTART_POLICIES",
    "RecordConfig",
    "RuntimeConfig",
    "build_nodes",
    "load_config",
    "parse_config",
]

LOG_LEVELS = ("debug", "info", "warning", "error")

_RUNTIME_KEYS = (
    "transport",
    "domain_id",
    "use_sim_time",
    "strict_qos",
    "log_level",
    "priority_realtime",
    "debug_messages",
    "parameters_file",
    "record",
    "foxglove",
    "zenoh_config",
    "iceoryx2_topics",
    "shutdown_timeout",
    "stall_threshold",
    "priority_stall_threshold",
    "late_threshold",
)
_NODE_KEYS = (
    "name", "use", "executor", "namespace", "parameters", "remap", "log_level", "parameters_file", "on_failure", "process"
)
#: what a node's failure to start does to the run (``[[nodes]] on_failure``)
ON_FAILURE = ("stop", "continue", "restart")
_RECORD_KEYS = ("path", "topics", "exclude", "compression", "max_bag_size", "max_bag_duration", "max_cache_size")
_FOXGLOVE_KEYS = ("host", "port", "max_large_hz", "asset_roots")
_TOP_KEYS = ("runtime", "nodes", "record", "processes")
#: ``[processes.<name>] restart``: when the supervisor starts a process again after it ended
RESTART_POLICIES = ("no", "on-failure", "always")
_PROCESS_KEYS = ("restart", "max_restarts", "restart_delay", "required")
#: the process of ``aiorobot run`` itself (nodes without ``process`` run there)
MAIN_PROCESS = "main"
_PROCESS_NAME = re.compile(r"^[A-Za-z][A-Za-z0-9_-]{0,62}$")

_BARE_KEY = re.compile(r"^[A-Za-z0-9_-]+$")
_USE = re.compile(
    r"^(?P<module>[A-Za-z_][A-Za-z0-9_]*(?:\.[A-Za-z_][A-Za-z0-9_]*)*)"
    r":(?P<attr>[A-Za-z_][A-Za-z0-9_]*(?:\.[A-Za-z_][A-Za-z0-9_]*)*)$"
)
_TOML_POSITION = re.compile(
    r"^(?P<msg>.*) \(at (?:line (?P<line>\d+), column (?P<col>\d+)|end of document)\)$"
)


@dataclass(frozen=True, slots=True)
class RuntimeConfig:
    """The ``[runtime]`` table: arguments of :class:`aiorobot.Runtime` and the default log level."""

    transport: str = "local"
    domain_id: int = 0
    use_sim_time: bool = False
    strict_qos: bool = False
    log_level: str = "info"
    priority_realtime: bool = False
    debug_messages: bool = False
    parameters_file: str | None = None  # a ROS 2 YAML parameter file for every node (absolute path)
    zenoh_config: str | None = None  # a zenoh session config file (JSON5) for routers, TLS, access control
    shutdown_timeout: float = SHUTDOWN_TIMEOUT_SEC
    stall_threshold: float = STALL_THRESHOLD_SEC
    priority_stall_threshold: float = PRIORITY_STALL_THRESHOLD_SEC
    late_threshold: float | None = LATE_THRESHOLD_SEC  # None (``false`` in the file): no culprit watch
    # topics whose large messages go over iceoryx2 between this graph's processes (``"*"``: every
    # topic of a type with arrays); ZenohTransport(iceoryx2_topics=)
    iceoryx2_topics: tuple[str, ...] = ()


@dataclass(frozen=True, slots=True)
class NodeConfig:
    """One ``[[nodes]]`` table.

    ``parameters`` holds flattened ROS-style names (a nested table ``{pid = {kp = 1.0}}``
    becomes ``"pid.kp"``); arrays are tuples. ``name`` and ``namespace`` are ``None`` when
    the file leaves them out (the node class chooses).
    """

    index: int
    use: str
    name: str | None = None
    executor: str = "main"
    namespace: str | None = None
    parameters: Mapping[str, Any] = field(default_factory=lambda: MappingProxyType({}))
    remap: Mapping[str, str] = field(default_factory=lambda: MappingProxyType({}))
    log_level: str | None = None
    parameters_file: str | None = None  # this node's ROS 2 YAML parameter file (absolute path)
    on_failure: str = "stop"
    process: str = "main"  # the process running this node (``aiorobot run`` itself: "main")

    @property
    def key(self) -> str:
        """The key path of this table, ``nodes[<index>]``."""
        return f"nodes[{self.index}]"

    @property
    def module_name(self) -> str:
        return self.use.partition(":")[0]

    @property
    def class_name(self) -> str:
        return self.use.partition(":")[2]


@dataclass(frozen=True, slots=True)
class RecordConfig:
    """The ``[record]`` table (or ``[runtime] record = {...}``): a rosbag2 (MCAP) recording of the run.

    ``topics`` empty records every topic (``exclude``: a regular expression of topics not to).
    """

    path: str
    topics: tuple[str, ...] = ()
    exclude: str = ""
    compression: str = "none"
    max_bag_size: int = 0
    max_bag_duration: float = 0.0
    max_cache_size: int = 0


@dataclass(frozen=True, slots=True)
class FoxgloveConfig:
    """``[runtime] foxglove = true`` or ``{ port = 8765, host = "127.0.0.1", max_large_hz = 10,
    asset_roots = ["meshes"] }`` (folders relative to the config file)."""

    host: str = "127.0.0.1"
    port: int = 8765
    max_large_hz: float = 10.0
    asset_roots: tuple[str, ...] = ()


@dataclass(frozen=True, slots=True)
class ProcessConfig:
    """One ``[processes.<name>]`` table: how ``aiorobot run`` supervises a child process.

    ``restart``: ``"no"`` (never start it again), ``"on-failure"`` (the default: again after
    a non-zero exit status or a death by a signal not sent by the supervisor) or
    ``"always"`` (after a clean exit too), as systemd's ``Restart=``. At most
    ``max_restarts`` restarts over the run; the n-th waits ``restart_delay * 2**(n-1)``
    seconds (capped at 30 s). When a ``required`` process ends and is not restarted, the
    whole graph shuts down (ROS launch's ``required``).
    """

    name: str
    restart: str = "on-failure"
    max_restarts: int = 5
    restart_delay: float = 1.0
    required: bool = False


@dataclass(frozen=True, slots=True)
class GraphConfig:
    """A validated configuration file."""

    path: str
    runtime: RuntimeConfig
    nodes: tuple[NodeConfig, ...]
    record: RecordConfig | None = None
    foxglove: FoxgloveConfig | None = None
    processes: Mapping[str, ProcessConfig] = field(default_factory=lambda: MappingProxyType({}))

    @property
    def child_processes(self) -> tuple[str, ...]:
        """The names of the processes other than ``main``, in the order of their first node."""
        return tuple(dict.fromkeys(n.process for n in self.nodes if n.process != MAIN_PROCESS))

    @property
    def base_dir(self) -> Path:
        """The folder holding the file: node modules are imported from there too."""
        return Path(self.path).resolve().parent


def load_config(path: str | Path) -> GraphConfig:
    """Read and validate a graph configuration file.

    Parameters
    ----------
    path : str or Path
        The TOML file; error messages name it as given here.

    Raises
    ------
    ConfigError
        The file cannot be read, is not UTF-8 TOML, or does not describe a valid graph.
    """
    try:
        raw = Path(path).read_bytes()
    except OSError as err:
        reason = err.strerror or type(err).__name__
        raise ConfigError(path, None, f"cannot read the file: {reason}") from None
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as err:
        line = raw[: err.start].count(b"\n") + 1
        raise ConfigError(
            path, None, f"line {line}: expected UTF-8 text, found the byte 0x{raw[err.start]:02x}"
        ) from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise ConfigError(path, None, _toml_error_message(str(err), text)) from None
    return parse_config(data, path)


def build_nodes(config: GraphConfig, process: str = MAIN_PROCESS) -> list[tuple[Any, str]]:
    """Import the node classes of ``config`` and construct the nodes: ``[(node, executor), ...]``.

    See :func:`aiorobot.launch.build_nodes` (imported lazily: this module stays pure).
    """
    from ._build import build_nodes as _build_nodes

    return _build_nodes(config, process)


def parse_config(data: Mapping[str, Any], path: str | Path = "<config>") -> GraphConfig:
    """Validate an already parsed TOML document (``tomllib.loads`` output)."""
    checker = _Checker(str(path))
    checker.check_keys(data, "", _TOP_KEYS)
    runtime_table = data.get("runtime", {})
    raw_nodes = data.get("nodes")
    multi_process = isinstance(raw_nodes, list) and any(
        isinstance(t, dict) and t.get("process", MAIN_PROCESS) != MAIN_PROCESS for t in raw_nodes
    )  # nodes in other processes meet over zenoh
    runtime = _parse_runtime(checker, runtime_table, default_transport="zenoh" if multi_process else "local")
    nodes = _parse_nodes(checker, data)
    record = None
    if "record" in data and "record" in runtime_table:
        raise checker.error("runtime.record", "the recording is set twice; keep either [record] or [runtime] record")
    if "record" in data:
        record = _parse_record(checker, data["record"], "record")
    elif "record" in runtime_table:
        record = _parse_record(checker, runtime_table["record"], "runtime.record")
    foxglove = _parse_foxglove(checker, runtime_table["foxglove"]) if "foxglove" in runtime_table else None
    processes = _parse_processes(checker, data.get("processes", {}), nodes)
    return GraphConfig(
        path=str(path), runtime=runtime, nodes=nodes, record=record, foxglove=foxglove,
        processes=MappingProxyType(processes),
    )


def _parse_processes(checker: _Checker, table: Any, nodes: tuple[NodeConfig, ...]) -> dict[str, ProcessConfig]:
    """One :class:`ProcessConfig` per child process named by a node (defaults where no table)."""
    checker.check_type(table, "processes", dict, "a table of [processes.<name>] tables")
    used = list(dict.fromkeys(n.process for n in nodes if n.process != MAIN_PROCESS))
    for name in table:
        key = checker.join("processes", name)
        if name == MAIN_PROCESS:
            raise checker.error(
                key, 'expected the name of a child process, found "main" (aiorobot run itself, never restarted)'
            )
        if name not in used:
            close = difflib.get_close_matches(name, used, n=1, cutoff=0.6)
            hint = f' (did you mean "{close[0]}"?)' if close else ""
            named = ", ".join(f'"{u}"' for u in used) or "none"
            raise checker.error(
                key, f'expected a process named by a [[nodes]] process key ({named}), found "{name}"{hint}'
            )
    processes = {}
    for name in used:
        sub = table.get(name, {})
        key = checker.join("processes", name)
        checker.check_type(sub, key, dict, 'a table such as { restart = "on-failure" }')
        checker.check_keys(sub, key, _PROCESS_KEYS)
        restart = checker.choice(sub, key, "restart", RESTART_POLICIES, "on-failure")
        max_restarts = sub.get("max_restarts", 5)
        checker.check_type(max_restarts, f"{key}.max_restarts", int, "an integer >= 0")
        if max_restarts < 0:
            raise checker.error(f"{key}.max_restarts", f"expected an integer >= 0, found {max_restarts}")
        delay = sub.get("restart_delay", 1.0)
        checker.check_type(delay, f"{key}.restart_delay", (int, float), "a number of seconds >= 0")
        if not delay >= 0 or not math.isfinite(delay):
            raise checker.error(f"{key}.restart_delay", f"expected a number of seconds >= 0, found {delay!r}")
        required = sub.get("required", False)
        checker.check_type(required, f"{key}.required", bool, "true or false")
        processes[name] = ProcessConfig(name, restart, max_restarts, float(delay), required)
    return processes


def _parse_runtime(checker: _Checker, table: Any, default_transport: str = "local") -> RuntimeConfig:
    """``default_transport`` is "zenoh" when a node runs in another process (processes meet over zenoh)."""
    checker.check_type(table, "runtime", dict, "a table ([runtime])")
    checker.check_keys(table, "runtime", _RUNTIME_KEYS)
    # the registry's names: "local", "zenoh" and any a package registered (aiorobot.register_transport)
    transport = checker.choice(table, "runtime", "transport", transport_names(), default_transport)
    if default_transport == "zenoh" and transport != "zenoh":
        raise checker.error(
            "runtime.transport",
            'a [[nodes]] process key puts a node in another process, which needs transport = "zenoh" '
            f'(or no transport key), found "{transport}"',
        )
    domain_id = table.get("domain_id", 0)
    checker.check_type(domain_id, "runtime.domain_id", int, f"an integer 0..{MAX_DOMAIN_ID}")
    if not 0 <= domain_id <= MAX_DOMAIN_ID:
        raise checker.error(
            "runtime.domain_id", f"expected an integer 0..{MAX_DOMAIN_ID}, found {domain_id}"
        )
    use_sim_time = table.get("use_sim_time", False)
    checker.check_type(use_sim_time, "runtime.use_sim_time", bool, "true or false")
    strict_qos = table.get("strict_qos", False)
    checker.check_type(strict_qos, "runtime.strict_qos", bool, "true or false")
    log_level = checker.choice(table, "runtime", "log_level", LOG_LEVELS, "info")
    realtime = table.get("priority_realtime", False)
    checker.check_type(realtime, "runtime.priority_realtime", bool, "true or false")
    debug_messages = table.get("debug_messages", False)
    checker.check_type(debug_messages, "runtime.debug_messages", bool, "true or false")
    parameters_file = _parameters_file(checker, table, "runtime")
    zenoh_config = table.get("zenoh_config")
    if zenoh_config is not None:
        checker.check_type(zenoh_config, "runtime.zenoh_config", str, "a path to a zenoh config file (JSON5)")
        resolved = (Path(checker.path).resolve().parent / zenoh_config).resolve()
        if not resolved.is_file():
            raise checker.error("runtime.zenoh_config", f"expected a zenoh config file, found no file at {resolved}")
        if transport != "zenoh":
            raise checker.error("runtime.zenoh_config", 'only applies with transport = "zenoh"')
        zenoh_config = str(resolved)
        from ..transport._session_config import check_session_file

        try:  # parses, its certificates are there, no plain endpoint past TLS: before anything starts
            check_session_file(zenoh_config)
        except ConfigError as err:
            raise checker.error("runtime.zenoh_config", str(err)) from None
    iceoryx2_topics = table.get("iceoryx2_topics", [])
    expected = 'a list of topic names, or ["*"] (every topic of a type with arrays)'
    checker.check_type(iceoryx2_topics, "runtime.iceoryx2_topics", list, expected)
    for topic in iceoryx2_topics:
        if not isinstance(topic, str) or not topic.strip("/ "):
            raise checker.error("runtime.iceoryx2_topics", f"expected {expected}, found {topic!r} in it")
    if iceoryx2_topics and transport != "zenoh":
        raise checker.error("runtime.iceoryx2_topics", 'only applies with transport = "zenoh"')
    seconds = {}
    for name, default in (
        ("shutdown_timeout", SHUTDOWN_TIMEOUT_SEC),
        ("stall_threshold", STALL_THRESHOLD_SEC),
        ("priority_stall_threshold", PRIORITY_STALL_THRESHOLD_SEC),
    ):
        value = table.get(name, default)
        checker.check_type(value, f"runtime.{name}", (int, float), "a number of seconds > 0")
        if isinstance(value, bool) or not value > 0:
            raise checker.error(f"runtime.{name}", f"expected a number of seconds > 0, found {value!r}")
        seconds[name] = float(value)
    late = table.get("late_threshold", LATE_THRESHOLD_SEC)
    if late is not False:
        checker.check_type(late, "runtime.late_threshold", (int, float), "a number of seconds > 0, or false (no watch)")
        if isinstance(late, bool) or not late > 0:
            raise checker.error("runtime.late_threshold", f"expected a number of seconds > 0 or false, found {late!r}")
    seconds["late_threshold"] = None if late is False else float(late)
    return RuntimeConfig(
        transport, domain_id, use_sim_time, strict_qos, log_level, realtime, debug_messages, parameters_file, zenoh_config,
        **seconds, iceoryx2_topics=tuple(iceoryx2_topics),
    )


def _parse_nodes(checker: _Checker, data: Mapping[str, Any]) -> tuple[NodeConfig, ...]:
    if "nodes" not in data:
        raise checker.error(
            "nodes", 'expected at least one [[nodes]] table with a "use" key, found none'
        )
    nodes = data["nodes"]
    if isinstance(nodes, dict):
        raise checker.error(
            "nodes", "expected an array of tables (write [[nodes]], not [nodes]), found a table"
        )
    checker.check_type(nodes, "nodes", list, "an array of tables ([[nodes]])")
    if not nodes:
        raise checker.error("nodes", "expected at least one node, found an empty array")
    return tuple(_parse_node(checker, i, table) for i, table in enumerate(nodes))


def _parse_node(checker: _Checker, index: int, table: Any) -> NodeConfig:
    key = f"nodes[{index}]"
    checker.check_type(table, key, dict, "a table")
    checker.check_keys(table, key, _NODE_KEYS)
    if "use" not in table:
        raise checker.error(
            f"{key}.use",
            'missing required key; expected a "module:Class" string such as '
            '"aiorobot.examples.sensor:ImuPublisher"',
        )
    use = table["use"]
    checker.check_type(use, f"{key}.use", str, 'a "module:Class" string')
    if not _USE.match(use):
        raise checker.error(
            f"{key}.use",
            f'expected "module:Class" (a dotted module path, a colon, a class name), found {_found(use)}',
        )

    name = table.get("name")
    if name is not None:
        checker.check_type(name, f"{key}.name", str, "a node name string")
        try:
            validate_node_name(name)
        except InvalidNameError as err:
            raise checker.error(f"{key}.name", _name_problem(err)) from None

    executor = checker.choice(table, key, "executor", EXECUTORS, "main")

    namespace = table.get("namespace")
    if namespace is not None:
        checker.check_type(namespace, f"{key}.namespace", str, 'a namespace string such as "/base"')
        try:
            namespace = validate_namespace(namespace)
        except InvalidNameError as err:
            raise checker.error(f"{key}.namespace", _name_problem(err)) from None

    parameters = table.get("parameters", {})
    checker.check_type(parameters, f"{key}.parameters", dict, "a table of parameter values")
    flat: dict[str, Any] = {}
    _flatten_parameters(checker, parameters, f"{key}.parameters", "", flat)

    remap = table.get("remap", {})
    checker.check_type(remap, f"{key}.remap", dict, 'a table of "from" = "to" names')
    for source, target in remap.items():
        source_key = checker.join(f"{key}.remap", source)
        if source.startswith("__"):
            replacement = {"__node": "name", "__ns": "namespace"}.get(source)
            hint = f"; set {key}.{replacement} instead" if replacement else ""
            raise checker.error(
                source_key, f"expected a topic or service name, found the special rule {_found(source)}{hint}"
            )
        for which, name_ in (("source", source), ("target", target)):
            checker.check_type(name_, source_key, str, "a topic or service name string")
            try:
                expand_name(name_, "node", "/", "topic")
            except InvalidNameError as err:
                raise checker.error(source_key, f"{which}: {_name_problem(err)}") from None

    log_level = checker.choice(table, key, "log_level", LOG_LEVELS, None)
    on_failure = checker.choice(table, key, "on_failure", ON_FAILURE, "stop")
    process = table.get("process", MAIN_PROCESS)
    checker.check_type(process, f"{key}.process", str, 'a process name such as "vision"')
    if not _PROCESS_NAME.match(process):
        raise checker.error(
            f"{key}.process",
            "expected a process name of letters, digits, '_' and '-' starting with a letter "
            f"(at most 63 characters), found {_found(process)}",
        )
    return NodeConfig(
        index=index,
        use=use,
        name=name,
        executor=executor,
        namespace=namespace,
        parameters=MappingProxyType(flat),
        remap=MappingProxyType(dict(remap)),
        log_level=log_level,
        parameters_file=_parameters_file(checker, table, key),
        on_failure=on_failure,
        process=process,
    )


def _parameters_file(checker: _Checker, table: Mapping[str, Any], key: str) -> str | None:
    """``parameters_file = "params.yaml"`` (relative to the config file): exists and parses."""
    from .._core._parameter_files import ParameterFileError, load_parameter_file

    if "parameters_file" not in table:
        return None
    value = table["parameters_file"]
    checker.check_type(value, f"{key}.parameters_file", str, "a path to a ROS 2 YAML parameter file")
    path = Path(value) if Path(value).is_absolute() else Path(checker.path).resolve().parent / value
    try:
        load_parameter_file(path)
    except FileNotFoundError:
        raise checker.error(f"{key}.parameters_file", f"expected an existing file, found no {str(path)!r}") from None
    except ParameterFileError as err:
        raise checker.error(f"{key}.parameters_file", str(err)) from None
    return str(path)


def _flatten_parameters(
    checker: _Checker, table: Mapping[str, Any], key: str, prefix: str, out: dict[str, Any]
) -> None:
    expected = "a boolean, integer, float, string or an array of one of these"
    for name, value in table.items():
        value_key = checker.join(key, name)
        if not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", name):
            raise checker.error(
                value_key,
                f"expected a parameter name of letters, digits and '_' not starting with a digit, "
                f"found {_found(name)}",
            )
        if isinstance(value, dict):
            _flatten_parameters(checker, value, value_key, f"{prefix}{name}.", out)
            continue
        if isinstance(value, list):
            kinds = {_scalar_kind(item) for item in value}
            if None in kinds:
                bad = next(item for item in value if _scalar_kind(item) is None)
                raise checker.error(value_key, f"expected {expected}, found an array holding {_found(bad)}")
            if kinds == {"integer", "float"}:
                value = [float(item) for item in value]
            elif len(kinds) > 1:
                raise checker.error(
                    value_key,
                    f"expected an array of one type, found an array mixing {' and '.join(sorted(str(k) for k in kinds))}",
                )
            out[prefix + name] = tuple(value)
            continue
        if _scalar_kind(value) is None:
            raise checker.error(value_key, f"expected {expected}, found {_found(value)}")
        out[prefix + name] = value


def _scalar_kind(value: Any) -> str | None:
    if isinstance(value, bool):
        return "boolean"
    if isinstance(value, int):
        return "integer"
    if isinstance(value, float):
        return "float"
    if isinstance(value, str):
        return "string"
    return None


def _parse_record(checker: _Checker, table: Any, key: str) -> RecordConfig:
    checker.check_type(table, key, dict, "a table such as { path = \"run\" }")
    checker.check_keys(table, key, _RECORD_KEYS)
    if "path" not in table:
        raise checker.error(f"{key}.path", 'missing required key; expected a bag directory name such as "run"')
    checker.check_type(table["path"], f"{key}.path", str, "a directory name string")
    topics = table.get("topics", [])
    checker.check_type(topics, f"{key}.topics", list, "a list of topic names")
    for i, topic in enumerate(topics):
        checker.check_type(topic, f"{key}.topics[{i}]", str, "a topic name string")
    exclude = table.get("exclude", "")
    checker.check_type(exclude, f"{key}.exclude", str, "a regular expression string")
    try:
        re.compile(exclude)
    except re.error as err:
        raise checker.error(f"{key}.exclude", f"expected a regular expression, found {exclude!r} ({err})") from None
    compression = checker.choice(table, key, "compression", ("none", "zstd", "lz4"), "none")
    numbers = {}
    for name, kind in (("max_bag_size", int), ("max_bag_duration", (int, float)), ("max_cache_size", int)):
        value = table.get(name, 0)
        checker.check_type(value, f"{key}.{name}", kind, "a number >= 0")
        if value < 0:
            raise checker.error(f"{key}.{name}", f"expected a number >= 0, found {value}")
        numbers[name] = value
    return RecordConfig(table["path"], tuple(topics), exclude, compression, int(numbers["max_bag_size"]),
                        float(numbers["max_bag_duration"]), int(numbers["max_cache_size"]))


def _parse_foxglove(checker: _Checker, value: Any) -> FoxgloveConfig | None:
    key = "runtime.foxglove"
    if isinstance(value, bool):
        return FoxgloveConfig() if value else None
    checker.check_type(value, key, dict, "true, false or a table such as { port = 8765 }")
    checker.check_keys(value, key, _FOXGLOVE_KEYS)
    host = value.get("host", "127.0.0.1")
    checker.check_type(host, f"{key}.host", str, "an address string")
    port = value.get("port", 8765)
    checker.check_type(port, f"{key}.port", int, "a port number 0..65535")
    if not 0 <= port <= 65535:
        raise checker.error(f"{key}.port", f"expected a port number 0..65535, found {port}")
    hz = value.get("max_large_hz", 10.0)
    checker.check_type(hz, f"{key}.max_large_hz", (int, float), "a rate in Hz > 0")
    if not hz > 0:
        raise checker.error(f"{key}.max_large_hz", f"expected a rate in Hz > 0, found {hz}")
    roots = value.get("asset_roots", [])
    checker.check_type(roots, f"{key}.asset_roots", list, "a list of folders")
    resolved = []
    for i, root in enumerate(roots):
        checker.check_type(root, f"{key}.asset_roots[{i}]", str, "a folder path")
        folder = (Path(checker.path).resolve().parent / root).resolve()
        if not folder.is_dir():
            raise checker.error(f"{key}.asset_roots[{i}]", f"expected a folder, found no folder at {folder}")
        resolved.append(str(folder))
    return FoxgloveConfig(host, port, float(hz), tuple(resolved))


class _Checker:
    """Builds :class:`ConfigError` for one file and holds the common checks."""

    def __init__(self, path: str) -> None:
        self.path = path

    def error(self, key: str | None, message: str) -> ConfigError:
        return ConfigError(self.path, key, message)

    @staticmethod
    def join(parent: str, name: str) -> str:
        part = name if _BARE_KEY.match(name) else json.dumps(name)
        return f"{parent}.{part}" if parent else part

    def check_keys(self, table: Mapping[str, Any], key: str, allowed: Iterable[str]) -> None:
        allowed = tuple(allowed)
        for name in table:
            if name not in allowed:
                close = difflib.get_close_matches(name, allowed, n=1, cutoff=0.6)
                hint = f', did you mean "{close[0]}"?' if close else ""
                raise self.error(
                    self.join(key, name),
                    f"unknown key{hint} (expected one of: {', '.join(allowed)})",
                )

    def check_type(self, value: Any, key: str, expected_type: type | tuple[type, ...], expected: str) -> None:
        ok = isinstance(value, expected_type)
        if expected_type is not bool and isinstance(value, bool):
            ok = False
        if not ok:
            raise self.error(key, f"expected {expected}, found {_found(value)}")

    def choice(
        self, table: Mapping[str, Any], parent: str, name: str, choices: tuple[str, ...], default: Any
    ) -> Any:
        key = self.join(parent, name)
        value = table.get(name, default)
        if value is default:
            return value
        if isinstance(value, str) and value.lower() in choices:
            return value.lower()
        quoted = [f'"{c}"' for c in choices]
        options = " or ".join(quoted) if len(quoted) == 2 else ", ".join(quoted[:-1]) + " or " + quoted[-1]
        hint = ""
        if isinstance(value, str):
            close = difflib.get_close_matches(value.lower(), choices, n=1, cutoff=0.6)
            hint = f' (did you mean "{close[0]}"?)' if close else ""
        raise self.error(key, f"expected {options}, found {_found(value)}{hint}")


def _found(value: Any) -> str:
    """Describe a TOML value the way the user wrote it, with its kind when that helps."""
    if isinstance(value, bool):
        return f"{'true' if value else 'false'} (a boolean)"
    if isinstance(value, int):
        return f"{value} (an integer)"
    if isinstance(value, float):
        text = repr(value) if math.isfinite(value) else str(value)
        return f"{text} (a float)"
    if isinstance(value, str):
        text = json.dumps(value, ensure_ascii=False)
        return text if len(text) <= 60 else text[:56] + '..."'
    if isinstance(value, dict):
        return "a table"
    if isinstance(value, list):
        return "an array"
    if isinstance(value, (datetime.datetime, datetime.date, datetime.time)):
        return f"a date/time ({value.isoformat()})"
    return repr(value)


def _name_problem(err: InvalidNameError) -> str:
    where = f" at index {err.index}" if err.index is not None else ""
    return f"invalid {err.kind} name {json.dumps(err.name)}: {err.reason}{where}"


def _toml_error_message(message: str, text: str) -> str:
    match = _TOML_POSITION.match(message)
    if match is None:
        return f"invalid TOML: {message}"
    reason = match["msg"]
    if match["line"] is None:
        line = text.count("\n") + (0 if text.endswith("\n") else 1)
        return f"line {max(line, 1)}: invalid TOML: {reason} (at the end of the file)"
    return f"line {match['line']}, column {match['col']}: invalid TOML: {reason}"
