"""ROS 2 YAML parameter files and ``cli_args`` (rclpy test_node.py::TestNodeParamsFile, test_parameter.py)."""

from __future__ import annotations

import textwrap

import pytest

from aiorobot import Node, Parameter, ParameterNotDeclaredError
from aiorobot.parameters import ParameterFileError, load_parameter_file, parameter_dict_from_yaml_file

# Every section kind of rclpy's wildcards.yaml resource, keys repeated as there.
WILDCARDS = """\
/**:
  ros__parameters:
    full_wild: full_wild
/**:
  node2:
    ros__parameters:
      namespace_wild: namespace_wild
/**/node2:
  ros__parameters:
    namespace_wild_another: namespace_wild_another
/*:
  node2:
    ros__parameters:
      namespace_wild_one_star: namespace_wild_one_star
ns:
  "*":
    ros__parameters:
      node_wild_in_ns: node_wild_in_ns
/ns/*:
  ros__parameters:
    node_wild_in_ns_another: node_wild_in_ns_another
ns:
  node2:
    ros__parameters:
      explicit_in_ns: explicit_in_ns
"*":
  ros__parameters:
    node_wild_no_ns: node_wild_no_ns
node2:
  ros__parameters:
    explicit_no_ns: explicit_no_ns
ns:
  nodeX:
    ros__parameters:
      should_not_appear: wrong_node
/**/nodeX:
  ros__parameters:
    should_not_appear: wrong_node
nsX:
  node2:
    ros__parameters:
      should_not_appear: wrong_namespace
/nsX/*:
  ros__parameters:
    should_not_appear: wrong_namespace
"""


@pytest.fixture
def wildcards(tmp_path):
    path = tmp_path / "wildcards.yaml"
    path.write_text(WILDCARDS)
    return str(path)


def _node(path, **kw):
    return Node("node2", cli_args=["--ros-args", "--params-file", path], automatically_declare_parameters_from_overrides=True, **kw)


def test_node_ns_params_file_with_wildcards(wildcards):
    # rclpy test_node.py::test_node_ns_params_file_with_wildcards
    node = _node(wildcards, namespace="/ns")
    for name in ("full_wild", "namespace_wild", "namespace_wild_another", "namespace_wild_one_star",
                 "node_wild_in_ns", "node_wild_in_ns_another", "explicit_in_ns"):
        assert node.get_parameter(name).value == name
    for name in ("node_wild_no_ns", "explicit_no_ns", "should_not_appear"):
        with pytest.raises(ParameterNotDeclaredError):
            node.get_parameter(name)


def test_node_params_file_with_wildcards(wildcards):
    # rclpy test_node.py::test_node_params_file_with_wildcards
    node = _node(wildcards)
    for name in ("full_wild", "namespace_wild", "namespace_wild_another", "node_wild_no_ns", "explicit_no_ns"):
        assert node.get_parameter(name).value == name
    for name in ("namespace_wild_one_star", "node_wild_in_ns", "node_wild_in_ns_another", "explicit_in_ns",
                 "should_not_appear"):
        with pytest.raises(ParameterNotDeclaredError):
            node.get_parameter(name)


def test_node_ns_params_file_by_order(tmp_path):
    # rclpy test_node.py::test_node_ns_params_file_by_order: a later match wins
    path = tmp_path / "order.yaml"
    path.write_text(textwrap.dedent("""\
        /**:
          node2:
            ros__parameters: {a_value: first, foo: foo}
        /ns:
          node2:
            ros__parameters: {a_value: second, bar: bar}
        /*:
          node2:
            ros__parameters: {a_value: last_one_win}
        """))
    node = _node(str(path), namespace="/ns")
    assert [node.get_parameter(n).value for n in ("a_value", "foo", "bar")] == ["last_one_win", "foo", "bar"]


def test_node_ns_params_file_with_complicated_wildcards(tmp_path):
    # rclpy test_node.py::test_node_ns_params_file_with_complicated_wildcards
    path = tmp_path / "complicated.yaml"
    path.write_text("/**/foo/*/bar:\n  node2:\n    ros__parameters: {foo: foo, bar: bar}\n")
    node = _node(str(path), namespace="/a/b/c/foo/d/bar")
    assert node.get_parameter("foo").value == "foo" and node.get_parameter("bar").value == "bar"
    assert "foo" not in _node(str(path), namespace="/a/foo/bar").list_parameters().names


def test_file_values_meet_declarations_and_nested_tables_flatten(tmp_path):
    path = tmp_path / "p.yaml"
    path.write_text(textwrap.dedent("""\
        /**:
          ros__parameters:
            use_sim_time: false
            unused_by_this_node: 3
        /robot/ctl:
          ros__parameters:
            gain: 2            # an int where a double is declared
            pid: {kp: 1.5, ki: 0.25}
            names: [a, b]
        """))
    node = Node("ctl", namespace="/robot", cli_args=["--ros-args", "--params-file", str(path), "-p", "pid.ki:=0.5"],
                parameter_overrides={"names": ["z"]})
    assert node.declare_parameter("gain", 1.0).value == 2.0
    # as rcl: the -p value joins the file's earlier /** section, so /robot/ctl's own value, later, wins
    assert node.declare_parameters("pid", [("kp", 0.0), ("ki", 0.0)])[1].value == 0.25
    assert node.declare_parameter("names", ["x"]).value == ["z"]  # parameter_overrides beat both
    assert node.unclaimed_parameter_overrides() == []  # file values for other nodes are not errors


def test_parameter_dict_from_yaml_file(tmp_path):
    # rclpy test_parameter.py::test_parameter_dict_from_yaml_file
    path = tmp_path / "p.yaml"
    path.write_text("/param_test_target:\n  ros__parameters:\n    param_1: 1\n    param_str: string\n")
    assert parameter_dict_from_yaml_file(str(path)) == {
        "param_1": Parameter("param_1", Parameter.Type.INTEGER, 1).to_parameter_msg(),
        "param_str": Parameter("param_str", Parameter.Type.STRING, "string").to_parameter_msg(),
    }
    with pytest.raises(FileNotFoundError):
        parameter_dict_from_yaml_file(str(tmp_path / "unknown_file"))
    with pytest.raises(RuntimeError, match="does not contain parameters for other"):
        parameter_dict_from_yaml_file(str(path), target_nodes=["other"])


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("a: [1, 2\n", "not valid YAML at line 2"),
        ("- 1\n", "expected a mapping of node names to sections, found list"),
        ("node:\n  ros__parameters: 5\n", "/node.ros__parameters: expected a mapping of parameters, found 5"),
        ("ros__parameters: {a: 1}\n", "ros__parameters: expected a node name (or /**) above ros__parameters"),
        ("node:\n  ros__parameters:\n    a: [[1]]\n", "/node.ros__parameters.a: expected a flat list of values"),
        ("node: 3\n", "node: expected a node section holding ros__parameters, found 3"),
    ],
)
def test_bad_files_get_one_line_naming_file_and_key(tmp_path, text, message):
    path = tmp_path / "bad.yaml"
    path.write_text(text)
    with pytest.raises(ParameterFileError) as info:
        load_parameter_file(path)
    assert str(info.value).startswith(str(path)) and message in str(info.value)
    assert "\n" not in str(info.value)
