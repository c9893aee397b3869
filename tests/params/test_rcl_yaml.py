"""Parameter files and ``-p`` values typed as rcl types them, applied in command-line order.

The YAML constructs are those of robot_localization's params/ekf.yaml, ukf.yaml and
dual_ekf_navsat_example.yaml (exponent floats without a dot, lists mixing ``1e-3`` and ``0.3``,
``/**`` and node-name sections, ``ros__parameters``), written here by the tests themselves.
"""

from __future__ import annotations

import math
import textwrap

import pytest

from aiorobot import InvalidParameterTypeError, Node, Parameter
from aiorobot._core._ros_args import RosArgsError, parse_ros_args
from aiorobot.parameters import ParameterFileError, load_parameter_file
from aiorobot._core._rcl_yaml import rcl_scalar

DUAL = """\
ekf_filter_node_odom:
  ros__parameters:
    frequency: 30.0
    two_d_mode: false
    debug_out_file: /path/to/debug/file.txt
    process_noise_covariance: [1e-3, 1e-3, 1e-3, 0.3, 0.3, 0.01, 0.5, 0.5, 0.1, 0.3, 0.3, 0.3, 0.3, 0.3, 0.3]
    initial_estimate_covariance: [1e-9, 1e-9, 1e-9, 1.0, 1.0, 1e-9, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0]
/**:
  ros__parameters:
    use_sim_time: true
"""


@pytest.mark.parametrize(
    ("text", "value"),
    [
        ("1e-9", 1e-9), ("1E3", 1000.0), ("5.", 5.0), (".5", 0.5), ("-1.5e+2", -150.0), ("0x1p3", 8.0),
        ("7", 7), ("-0", 0), ("+5", 5), ("0x1F", 31), ("010", 8), ("08", 8.0), ("99999999999999999999", 1e20),
        ("true", True), ("On", True), ("y", True), ("N", False), ("off", False),
        (".inf", math.inf), ("-.Inf", -math.inf), ("inf", math.inf),
        ("1_000", "1_000"), ("null", "null"), ("~", "~"), ("2024-01-01", "2024-01-01"), ("1e", "1e"),
        ("1e999", "1e999"), ("1e-400", "1e-400"), ("yes please", "yes please"),
    ],
)  # fmt: skip
def test_scalars_are_typed_as_rcl_get_value_types_them(text, value):
    assert rcl_scalar(text) == value and type(rcl_scalar(text)) is type(value)


def test_nan_and_quoted_scalars():
    assert math.isnan(rcl_scalar(".nan")) and math.isnan(rcl_scalar("NaN"))
    assert rcl_scalar("1e-9", quoted=True) == "1e-9"


def test_exponent_floats_and_mixed_lists_load_as_doubles(tmp_path):
    path = tmp_path / "dual.yaml"
    path.write_text(DUAL)
    values = load_parameter_file(path).for_node("/ekf_filter_node_odom")
    assert values["process_noise_covariance"][:4] == [1e-3, 1e-3, 1e-3, 0.3]
    assert all(type(v) is float for v in values["process_noise_covariance"] + values["initial_estimate_covariance"])
    assert values["use_sim_time"] is True and values["debug_out_file"] == "/path/to/debug/file.txt"
    assert Parameter("p", value=values["initial_estimate_covariance"]).type_ is Parameter.Type.DOUBLE_ARRAY
    node = Node("ekf_filter_node_odom", cli_args=["--ros-args", "--params-file", str(path)])
    got = node.declare_parameter("initial_estimate_covariance", [0.0] * 15).value
    assert got[0] == 1e-9 and got[3] == 1.0


def test_strings_stay_strings_where_quoted_or_tagged(tmp_path):
    path = tmp_path / "p.yaml"
    path.write_text('n:\n  ros__parameters:\n    a: "1e-9"\n    b: !!str 5\n    c: !!float 5\n    d: [1, 2.5]\n')
    assert load_parameter_file(path).for_node("/n") == {"a": "1e-9", "b": "5", "c": 5, "d": [1.0, 2.5]}


@pytest.mark.parametrize(
    ("body", "message"),
    [
        ("n:\n  ros__parameters:\n    a: [true, 1e-9]\n", "n.ros__parameters.a: expected a list of one type (as rcl), found bool and double values in the list (line 3)"),
        ("n:\n  ros__parameters:\n    a:\n", "n.ros__parameters.a: expected a value, found none (line 3)"),
        ("n:\n  ros__parameters:\n    a: &x 1\n    b: *x\n", "not valid YAML at line 4: aliases are not supported"),
    ],
)  # fmt: skip
def test_bad_values_name_the_file_key_and_line(tmp_path, body, message):
    path = tmp_path / "bad.yaml"
    path.write_text(body)
    with pytest.raises(ParameterFileError) as info:
        load_parameter_file(path)
    assert str(info.value).startswith(f"{path}: ") and message in str(info.value)


def test_a_refused_file_value_names_the_yaml_file_and_key(tmp_path):
    path = tmp_path / "p.yaml"
    path.write_text("/**:\n  ros__parameters:\n    rate: fast\n")
    node = Node("n", cli_args=["--ros-args", "--params-file", str(path)])
    with pytest.raises(InvalidParameterTypeError) as info:
        node.declare_parameter("rate", 1.0)
    assert str(info.value) == (
        f"parameter 'rate': expected double, found string 'fast' (from {path}: /**.ros__parameters.rate (line 3))"
    )
    node = Node("n", cli_args=["--ros-args", "-p", "rate:=fast"])
    with pytest.raises(InvalidParameterTypeError, match=r"\(from --ros-args -p rate\)$"):
        node.declare_parameter("rate", 1.0)


def test_dash_p_values_are_typed_as_rcl_types_them():
    args = parse_ros_args(["--ros-args", "-p", "a:=1e-9", "-p", "b:=[1e-3, 0.3]", "-p", "c:=y", "-p", "d:=null"])
    assert args.parameters_for("n") == {"a": 1e-9, "b": [1e-3, 0.3], "c": True, "d": "null"}
    with pytest.raises(RosArgsError, match=r"^-p a:=\{b: 1\}: expected a value or a \[list\], found a mapping"):
        parse_ros_args(["--ros-args", "-p", "a:={b: 1}"])


def test_overrides_apply_in_command_line_order(tmp_path):
    # rclpy test_node.py::TestNode::test_declare_parameter: its test_parameters.yaml resource and cli_args
    path = tmp_path / "test_parameters.yaml"
    path.write_text(textwrap.dedent("""\
        /**:
          ros__parameters:
            initial_fizz: -23
            initial_baz: 1.0
            initial_foobar: False
        /my_ns/my_node:
          ros__parameters:
            initial_fizz: param_file_override
        """))
    node = Node(
        "my_node",
        namespace="/my_ns",
        parameter_overrides=[Parameter("initial_foo", Parameter.Type.INTEGER, 4321),
                             Parameter("initial_baz", Parameter.Type.DOUBLE, 3.14)],
        cli_args=["--ros-args", "-p", "initial_fizz:=buzz", "--params-file", str(path), "-p", "initial_buzz:=1."],
    )  # fmt: skip
    assert node.declare_parameter("initial_fizz", "default").value == "param_file_override"  # CLI, then the file
    assert node.declare_parameter("initial_baz", 0.0).value == 3.14  # the file, then parameter_overrides
    assert node.declare_parameter("initial_buzz", 0.0).value == 1.0  # CLI
    assert node.declare_parameter("initial_foobar", True).value is False  # the file
    assert node.declare_parameter("initial_foo", 0).value == 4321
    # the other way round, the -p value comes last in its section and wins
    late = Node("my_node", namespace="/my_ns", cli_args=["--ros-args", "--params-file", str(path), "-p", "initial_baz:=2.5"])
    assert late.declare_parameter("initial_baz", 0.0).value == 2.5
    # node-targeted -p rules form the section "/<name>", as rcl: they reach the node of that fully qualified name
    targeted = Node("my_node", cli_args=["--ros-args", "-p", "my_node:initial_baz:=4.5", "-p", "other:initial_baz:=9.0"])
    assert targeted.declare_parameter("initial_baz", 0.0).value == 4.5


def test_special_floats_as_rcl_test_parse_yaml_special_float_point(tmp_path):
    # rcl_yaml_param_parser test_parse_yaml.cpp special_float_point (its special_float.yaml constructs)
    path = tmp_path / "special_float.yaml"
    path.write_text(
        "test_node:\n  ros__parameters:\n"
        "    isstring: [string, .nananan, .nAN, .Nan, .infinf, .INf, .infinity]\n"
        "    nan_inf: [1.1, 2.2, .nan, .NAN, .inf, +.Inf, -.INF]\n"
    )
    values = load_parameter_file(path).for_node("/test_node")
    assert values["isstring"] == ["string", ".nananan", ".nAN", ".Nan", ".infinf", ".INf", ".infinity"]
    nan_inf = values["nan_inf"]
    assert nan_inf[:2] == [1.1, 2.2] and math.isnan(nan_inf[2]) and math.isnan(nan_inf[3])
    assert nan_inf[4:] == [math.inf, math.inf, -math.inf]
