"""The pure half of the config loader: reading, TOML parsing and validation (no node is built)."""

from __future__ import annotations

import dataclasses
import re
from pathlib import Path

import pytest

from aiorobot.launch import ConfigError, GraphConfig, NodeConfig, RuntimeConfig, load_config

CONFIGS = Path(__file__).parent / "configs"
BAD_PARSE = sorted((CONFIGS / "bad").glob("*.toml"))


def expected_message(path: Path) -> str:
    """A bad fixture's first line is ``# expect: <the error after "<file>: ">``."""
    first = path.read_text(encoding="utf-8").splitlines()[0]
    assert first.startswith("# expect: "), f"{path} must start with '# expect: '"
    return f"{path}: {first.removeprefix('# expect: ')}"


def write(tmp_path: Path, text: str, name: str = "graph.toml") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


@pytest.mark.parametrize("path", BAD_PARSE, ids=lambda p: p.stem)
def test_bad_config_raises_one_line_error_naming_file_key_expected_and_found(path: Path) -> None:
    with pytest.raises(ConfigError, match=rf"^{re.escape(expected_message(path))}$") as info:
        load_config(path)
    assert "\n" not in str(info.value)
    assert info.value.path == str(path)


def test_error_carries_path_key_and_message_separately(tmp_path: Path) -> None:
    path = write(tmp_path, '[[nodes]]\nuse = "m:C"\nexecutor = "fast"\n')
    with pytest.raises(ConfigError) as info:
        load_config(path)
    assert (info.value.path, info.value.key) == (str(path), "nodes[0].executor")
    assert info.value.message == 'expected "main" or "priority", found "fast"'


def test_missing_file_is_reported_as_unreadable(tmp_path: Path) -> None:
    path = tmp_path / "nope.toml"
    with pytest.raises(ConfigError, match=rf"^{re.escape(str(path))}: cannot read the file: No such file or directory$"):
        load_config(path)


def test_directory_is_reported_as_unreadable(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match=r": cannot read the file: Is a directory$"):
        load_config(tmp_path)


def test_non_utf8_file_names_the_line_and_byte(tmp_path: Path) -> None:
    path = tmp_path / "latin1.toml"
    path.write_bytes(b'[[nodes]]\nuse = "caf\xe9:C"\n')
    with pytest.raises(ConfigError, match=r": line 2: expected UTF-8 text, found the byte 0xe9$"):
        load_config(path)


def test_toml_error_at_end_of_file_names_the_last_line(tmp_path: Path) -> None:
    path = write(tmp_path, "[[nodes]]\nuse =")
    with pytest.raises(
        ConfigError, match=r": line 2: invalid TOML: Invalid value \(at the end of the file\)$"
    ):
        load_config(path)


def test_minimal_config_takes_documented_defaults(tmp_path: Path) -> None:
    config = load_config(write(tmp_path, '[[nodes]]\nuse = "my_nodes:Talker"\n'))
    assert config.runtime == RuntimeConfig(
        transport="local", domain_id=0, use_sim_time=False, strict_qos=False, log_level="info"
    )
    (node,) = config.nodes
    assert (node.use, node.name, node.executor, node.namespace, node.log_level) == (
        "my_nodes:Talker",
        None,
        "main",
        None,
        None,
    )
    assert dict(node.parameters) == {} and dict(node.remap) == {}
    assert config.record is None
    assert config.base_dir == tmp_path.resolve()


def test_full_config_is_parsed_into_frozen_dataclasses(tmp_path: Path) -> None:
    text = """
[runtime]
transport = "local"
domain_id = 232
use_sim_time = true
strict_qos = true
log_level = "Warning"

[[nodes]]
name = "controller"
use = "aiorobot.control:MecanumController"
executor = "priority"
namespace = "/base"
parameters = { max_speed = 0.5, wheels = [1, 2.5], pid = { kp = 1.0, ki = 0 }, frame = "base_link", on = true }
remap = { "/cmd_vel" = "/base/cmd_vel", "~/out" = "out" }
log_level = "debug"

[[nodes]]
use = "my_nodes:Talker"
namespace = "robot"
"""
    config = load_config(write(tmp_path, text))
    assert isinstance(config, GraphConfig)
    assert config.runtime == RuntimeConfig("local", 232, True, True, "warning")
    controller, talker = config.nodes
    assert controller == NodeConfig(
        index=0,
        use="aiorobot.control:MecanumController",
        name="controller",
        executor="priority",
        namespace="/base",
        parameters=controller.parameters,
        remap=controller.remap,
        log_level="debug",
    )
    assert dict(controller.parameters) == {
        "max_speed": 0.5,
        "wheels": (1.0, 2.5),
        "pid.kp": 1.0,
        "pid.ki": 0,
        "frame": "base_link",
        "on": True,
    }
    assert dict(controller.remap) == {"/cmd_vel": "/base/cmd_vel", "~/out": "out"}
    assert (controller.module_name, controller.class_name, controller.key) == (
        "aiorobot.control",
        "MecanumController",
        "nodes[0]",
    )
    assert talker.namespace == "/robot", "a relative namespace is made absolute"
    with pytest.raises(dataclasses.FrozenInstanceError):
        config.nodes[0].executor = "main"  # type: ignore[misc]
    with pytest.raises(TypeError):
        controller.parameters["max_speed"] = 1.0  # type: ignore[index]


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("[runtime]\nstrict_qos = 1\n", "runtime.strict_qos: expected true or false, found 1 (an integer)"),
        ("[runtime]\ndomain_id = true\n", "runtime.domain_id: expected an integer 0..232, found true (a boolean)"),
        ("[runtime]\ndomain_id = -1\n", "runtime.domain_id: expected an integer 0..232, found -1"),
        ("runtime = 3\n", "runtime: expected a table ([runtime]), found 3 (an integer)"),
        ("nodes = []\n", "nodes: expected at least one node, found an empty array"),
        ("nodes = [1]\n", "nodes[0]: expected a table, found 1 (an integer)"),
        ('[[nodes]]\nuse = "m:C"\nname = 3\n', "nodes[0].name: expected a node name string, found 3 (an integer)"),
        (
            '[[nodes]]\nuse = "m:C"\nname = "9lives"\n',
            'nodes[0].name: invalid node name "9lives": must not start with a digit at index 0',
        ),
        (
            '[[nodes]]\nuse = "m:C"\nexecutor = "Priorty"\n',
            'nodes[0].executor: expected "main" or "priority", found "Priorty" (did you mean "priority"?)',
        ),
        (
            '[[nodes]]\nuse = "m:C"\nlog_level = 10\n',
            'nodes[0].log_level: expected "debug", "info", "warning" or "error", found 10 (an integer)',
        ),
        (
            '[[nodes]]\nuse = "m:C"\nremap = { "/a" = 1 }\n',
            'nodes[0].remap."/a": expected a topic or service name string, found 1 (an integer)',
        ),
        (
            '[[nodes]]\nuse = "m:C"\nremap = { "a b" = "c" }\n',
            "nodes[0].remap.\"a b\": source: invalid topic name \"a b\": character ' ' is not allowed "
            "(letters, digits, '_', '/', '~' and {} only) at index 1",
        ),
        (
            '[[nodes]]\nuse = "m:C"\nremap = { __ns = "/x" }\n',
            'nodes[0].remap.__ns: expected a topic or service name, found the special rule "__ns"; '
            "set nodes[0].namespace instead",
        ),
        (
            '[[nodes]]\nuse = "m:C"\nparameters = { rates = [[1], [2]] }\n',
            "nodes[0].parameters.rates: expected a boolean, integer, float, string or an array of one "
            "of these, found an array holding an array",
        ),
        (
            '[[nodes]]\nuse = "m:C"\nparameters = { "max speed" = 1 }\n',
            'nodes[0].parameters."max speed": expected a parameter name of letters, digits and \'_\' '
            'not starting with a digit, found "max speed"',
        ),
        (
            '[[nodes]]\nuse = "m:C"\n[record]\nfile = "x.mcap"\n',
            'record.file: unknown key (expected one of: path, topics, exclude, compression, max_bag_size, max_bag_duration, max_cache_size)',
        ),
        ('[[nodes]]\nuse = "m:C"\n[record]\n', 'record.path: missing required key; expected a bag directory name such as "run"'),
        ('[[nodes]]\nuse = "m:C"\n[record]\npath = "r"\ncompression = "gzip"\n', 'record.compression: expected "none", "zstd" or "lz4", found "gzip"'),
        ('[[nodes]]\nuse = "m:C"\n[record]\npath = "r"\nexclude = "(("\n', "record.exclude: expected a regular expression, found '((' (missing ), unterminated subpattern at position 1)"),
        ('[runtime]\nrecord = { path = "a" }\n[[nodes]]\nuse = "m:C"\n[record]\npath = "b"\n', "runtime.record: the recording is set twice; keep either [record] or [runtime] record"),
        ('[runtime]\nfoxglove = { port = 70000 }\n[[nodes]]\nuse = "m:C"\n', "runtime.foxglove.port: expected a port number 0..65535, found 70000"),
        ('[runtime]\nfoxglove = "yes"\n[[nodes]]\nuse = "m:C"\n', 'runtime.foxglove: expected true, false or a table such as { port = 8765 }, found "yes"'),
        (
            '[[nodes]]\nuse = ":C"\n',
            'nodes[0].use: expected "module:Class" (a dotted module path, a colon, a class name), found ":C"',
        ),
    ],
)
def test_each_invalid_value_names_its_key_path(tmp_path: Path, text: str, expected: str) -> None:
    path = write(tmp_path, text)
    with pytest.raises(ConfigError, match=rf"^{re.escape(f'{path}: {expected}')}$"):
        load_config(path)


def test_first_problem_in_file_order_is_reported(tmp_path: Path) -> None:
    text = '[[nodes]]\nuse = "m:C"\nexecutor = "fast"\n[[nodes]]\nuses = "m:C"\n'
    with pytest.raises(ConfigError, match=r": nodes\[0\]\.executor: "):
        load_config(write(tmp_path, text))


def test_unknown_key_without_a_close_match_lists_the_allowed_keys(tmp_path: Path) -> None:
    path = write(tmp_path, '[[nodes]]\nuse = "m:C"\nzzz = 1\n')
    with pytest.raises(
        ConfigError,
        match=r"^.*: nodes\[0\]\.zzz: unknown key \(expected one of: name, use, executor, namespace, "
        r"parameters, remap, log_level, parameters_file, on_failure, process\)$",
    ):
        load_config(path)


def test_multiline_messages_are_folded_into_one_line() -> None:
    err = ConfigError("a.toml", "nodes[0]", "first line\n  second line\n")
    assert str(err) == "a.toml: nodes[0]: first line second line"
    assert str(ConfigError("a.toml", None, "cannot read")) == "a.toml: cannot read"


def test_priority_realtime_reaches_the_runtime(tmp_path):
    from aiorobot import Runtime

    path = tmp_path / "rt.toml"
    path.write_text(
        '[runtime]\npriority_realtime = true\ndebug_messages = true\n\n[[nodes]]\nuse = "aiorobot.examples.sensor:ImuPublisher"\n'
    )
    assert load_config(path).runtime.priority_realtime is True
    runtime = Runtime(config=path)
    assert runtime._priority_realtime is True and runtime._bus.debug_messages is True
