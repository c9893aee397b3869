"""The ``--ros-args`` parser (rcl's grammar) and ``aiorobot run module:Class --ros-args ...``."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap

import pytest

from aiorobot import Node
from aiorobot._core._ros_args import RosArgsError, parse_ros_args, strip_ros_args


def test_parameters_remaps_files_and_levels():
    args = parse_ros_args([
        "prog_arg", "--ros-args", "-p", "rate:=5.0", "--param", "names:=[a, b]", "-p", "talker:only:=true",
        "-r", "/scan:=/base/scan", "--remap", "__node:=x", "-r", "talker:__ns:=/y",
        "--params-file", "a.yaml", "--params-file", "b.yaml", "--log-level", "WARN", "--log-level", "rcl:=debug",
        "--enable-rosout-logs", "-e", "/enc", "--", "tail",
    ])
    assert args.unparsed == ["prog_arg", "tail"]
    assert args.parameters_for("listener") == {"rate": 5.0, "names": ["a", "b"]}
    assert args.parameters_for("talker") == {"rate": 5.0, "names": ["a", "b"], "only": True}
    assert args.remappings_for("listener") == {"/scan": "/base/scan", "__node": "x"}
    assert args.remappings_for("talker")["__ns"] == "/y"
    assert args.params_files == ["a.yaml", "b.yaml"]
    assert args.log_level == "warning" and args.log_levels["rcl"] == "debug"


def test_values_are_read_as_yaml_like_ros2_param_set():
    # rclpy parameter.py get_parameter_value: the types -p gives
    args = parse_ros_args(["--ros-args", "-p", "i:=3", "-p", "f:=3.5", "-p", "b:=false", "-p", "s:=hello",
                           "-p", "e:=", "-p", "l:=[1, 2]"])
    assert args.parameters_for("n") == {"i": 3, "f": 3.5, "b": False, "s": "hello", "e": "", "l": [1, 2]}


def test_several_ros_args_sections():
    args = parse_ros_args(["--ros-args", "-p", "a:=1", "--", "x", "--ros-args", "-p", "b:=2"])
    assert args.unparsed == ["x"] and args.parameters_for("n") == {"a": 1, "b": 2}
    assert strip_ros_args(["a", "--ros-args", "-r", "x:=y", "--", "b"]) == ["a", "b"]


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--ros-args", "-p"], "-p: expected a value after it, found nothing"),
        (["--ros-args", "-p", "novalue"], "-p: expected [node:]name:=value, found 'novalue'"),
        (["--ros-args", "-r", ":=x"], "-r: expected [node:]from:=to, found ':=x'"),
        (["--ros-args", "--log-level", "loud"], "--log-level: expected a level"),
        (["--ros-args", "--bogus"], "unknown ROS argument '--bogus' after --ros-args"),
        (["--ros-args", "--params-file", "--"], "--params-file: expected a value after it, found '--'"),
    ],
)
def test_bad_ros_args_say_what_was_expected(argv, message):
    with pytest.raises(RosArgsError) as info:
        parse_ros_args(argv)
    assert message in str(info.value)


def test_node_cli_args_apply_remaps_parameters_and_level(tmp_path):
    # rclpy test_node.py::test_node_resolve_name (-r foo:=bar) and cli_args overrides
    node = Node("n", namespace="/my_ns", cli_args=["--ros-args", "-r", "foo:=bar", "-p", "k:=2", "--log-level", "error"])
    assert node.resolve_topic_name("foo") == "/my_ns/bar"
    assert node.resolve_topic_name("/abs") == "/abs"
    assert node.declare_parameter("k", 1).value == 2
    assert node.get_logger().get_effective_level() == 40
    renamed = Node("n", cli_args=["--ros-args", "-r", "__node:=m", "-r", "__ns:=/z"])
    assert renamed.get_fully_qualified_name() == "/z/m"
    with pytest.raises(TypeError):
        Node("n", cli_args="--ros-args")  # type: ignore[arg-type]


NODE_MODULE = """
from aiorobot import Node

class Talker(Node):
    def __init__(self, **kw):
        super().__init__("talker", **kw)
        rate = self.declare_parameter("rate", 1.0).value
        gain = self.declare_parameter("gain", 0.0).value
        print(f"fqn={self.get_fully_qualified_name()} rate={rate!r} gain={gain!r} "
              f"topic={self.resolve_topic_name('chatter')}", flush=True)

class Fixed(Node):
    def __init__(self):
        super().__init__("fixed")
"""


def _run(tmp_path, *args):
    env = dict(os.environ)
    env.pop("PYTHONWARNINGS", None)
    return subprocess.run([sys.executable, "-m", "aiorobot.cli", "run", *args], capture_output=True, text=True,
                          timeout=120, cwd=tmp_path, env=env)


def test_aiorobot_run_module_class_with_ros_args(tmp_path):
    (tmp_path / "my_nodes.py").write_text(NODE_MODULE)
    (tmp_path / "p.yaml").write_text(textwrap.dedent("""\
        /**:
          ros__parameters: {gain: 0.5, rate: 2.0}
        """))
    done = _run(tmp_path, "my_nodes:Talker", "--duration", "0.1", "--ros-args", "-p", "rate:=5", "-r", "__node:=x",
                "-r", "__ns:=/y", "-r", "chatter:=talk", "--params-file", "p.yaml")
    assert done.returncode == 0, done.stderr
    # -p rate:=5 comes before the file on the command line: the file's rate wins, as with rcl
    assert "fqn=/y/x rate=2.0 gain=0.5 topic=/y/talk" in done.stdout
    assert "Traceback" not in done.stderr


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["my_nodes:Talker", "--ros-args", "-p", "rate:=fast"], "parameter 'rate': expected double, found string 'fast'"),
        (["my_nodes:Talker", "--ros-args", "--params-file", "missing.yaml"], "--params-file: no such file 'missing.yaml'"),
        (["my_nodes:Nope"], 'module "my_nodes" has no class "Nope"'),
        (["no_such_module:Talker"], 'module "no_such_module" was not found'),
        (["my_nodes:Fixed", "--ros-args", "-p", "a:=1"], "cannot take ROS arguments"),
    ],
)
def test_aiorobot_run_bad_node_arguments_are_one_line(tmp_path, args, message):
    (tmp_path / "my_nodes.py").write_text(NODE_MODULE)
    done = _run(tmp_path, *args)
    assert done.returncode == 2
    assert done.stderr.count("\n") == 1 and message in done.stderr, done.stderr


def test_log_level_for_one_logger_applies_to_that_node():
    node = Node("talker", cli_args=["--ros-args", "--log-level", "info", "--log-level", "talker:=debug"])
    other = Node("listener", cli_args=["--ros-args", "--log-level", "info", "--log-level", "talker:=debug"])
    assert node.get_logger().get_effective_level() == 10
    assert other.get_logger().get_effective_level() == 20


def test_ros_args_with_a_config_file_is_refused(tmp_path):
    done = _run(tmp_path, "graph.toml", "--ros-args", "-p", "a:=1")
    assert done.returncode == 2 and "--ros-args needs a module:Class, not a config file" in done.stderr
