"""``parameters_file`` in a TOML config: per node and runtime-wide, under inline ``parameters``."""

from __future__ import annotations

import textwrap

import pytest

from aiorobot import Node
from aiorobot.launch import ConfigError, build_nodes, load_config

NODES = """
from aiorobot import Node

class Ctl(Node):
    def __init__(self, **kw):
        super().__init__("ctl", **kw)
        self.gain = self.declare_parameter("gain", 0.0).value
        self.rate = self.declare_parameter("rate", 1.0).value
        self.mode = self.declare_parameter("mode", "auto").value
"""


def _write(tmp_path, toml, files):
    (tmp_path / "param_file_nodes.py").write_text(NODES)
    for name, text in files.items():
        (tmp_path / name).write_text(textwrap.dedent(text))
    path = tmp_path / "graph.toml"
    path.write_text(textwrap.dedent(toml))
    return path


@pytest.fixture(autouse=True)
def _forget_module():
    import sys

    yield
    sys.modules.pop("param_file_nodes", None)


def test_runtime_and_node_files_layer_under_inline_parameters(tmp_path):
    path = _write(
        tmp_path,
        """\
        [runtime]
        parameters_file = "all.yaml"

        [[nodes]]
        use = "param_file_nodes:Ctl"
        namespace = "/left"
        parameters_file = "left.yaml"
        parameters = { mode = "manual" }

        [[nodes]]
        use = "param_file_nodes:Ctl"
        namespace = "/right"
        """,
        {
            "all.yaml": """\
                /**:
                  ros__parameters: {gain: 1.0, rate: 10.0, mode: from_file, other_nodes_param: 1}
                """,
            "left.yaml": """\
                /left/ctl:
                  ros__parameters: {rate: 20}
                /right/ctl:
                  ros__parameters: {rate: 99.0}
                """,
        },
    )
    config = load_config(path)
    assert config.runtime.parameters_file == str(tmp_path / "all.yaml")
    (left, _), (right, _) = build_nodes(config)
    assert (left.gain, left.rate, left.mode) == (1.0, 20.0, "manual")
    assert (right.gain, right.rate, right.mode) == (1.0, 10.0, "from_file")  # left.yaml is left's only
    assert isinstance(left, Node)


@pytest.mark.parametrize(
    ("setting", "files", "message"),
    [
        ('parameters_file = "missing.yaml"', {}, "nodes[0].parameters_file: expected an existing file, found no"),
        ("parameters_file = 3", {}, "nodes[0].parameters_file: expected a path to a ROS 2 YAML parameter file"),
        ('parameters_file = "bad.yaml"', {"bad.yaml": "- 1\n"}, "expected a mapping of node names to sections"),
    ],
)
def test_bad_parameters_file_is_a_config_error(tmp_path, setting, files, message):
    path = _write(tmp_path, f'[[nodes]]\nuse = "param_file_nodes:Ctl"\n{setting}\n', files)
    with pytest.raises(ConfigError) as info:
        load_config(path)
    assert message in str(info.value) and "\n" not in str(info.value)


def test_wrongly_typed_file_value_names_the_parameter(tmp_path):
    path = _write(
        tmp_path,
        '[[nodes]]\nuse = "param_file_nodes:Ctl"\nparameters_file = "p.yaml"\n',
        {"p.yaml": "/**:\n  ros__parameters: {rate: fast}\n"},
    )
    with pytest.raises(ConfigError, match="rate.*expected double, found string 'fast'"):
        build_nodes(load_config(path))


def test_a_refused_file_value_names_the_yaml_file_and_key_not_a_toml_key(tmp_path):
    path = _write(tmp_path, """\
        [[nodes]]
        use = "param_file_nodes:Ctl"
        parameters_file = "ctl.yaml"
        """, {"ctl.yaml": """\
        ctl:
          ros__parameters:
            rate: 1e-3
            gain: high
        """})  # fmt: skip
    with pytest.raises(ConfigError) as info:
        build_nodes(load_config(path))
    assert str(info.value) == (
        f"{path}: nodes[0].parameters_file: parameter 'gain': expected double, found string 'high' "
        f"(from {tmp_path / 'ctl.yaml'}: /ctl.ros__parameters.gain (line 4))"
    )
