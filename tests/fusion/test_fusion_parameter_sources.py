"""The same filter parameters from code, a TOML table, ``--ros-args -p`` and a ROS 2 parameter file
build the same node: same inputs and subscriptions, same values, same "has no effect" warnings.

The values and their spelling follow robot_localization's params/ekf.yaml and
dual_ekf_navsat_example.yaml (exponent floats without a dot, lists mixing ``1e-3`` and ``0.3``);
the files are written here, not copied.
"""

from __future__ import annotations

import logging

import pytest

from aiorobot import Node
from aiorobot.fusion import EkfNode, UkfNode

ODOM = [True, True, False, False, False, False, False, False, False, False, False, True, False, False, False]
IMU = [False, False, False, True, True, True, False, False, False, True, True, True, True, True, True]
POSE = [True, True, False] + [False] * 12
TWIST = [False] * 6 + [True, True, True] + [False] * 6
VALUES = {
    "frequency": 30.0,
    "two_d_mode": False,
    "debug": False,
    "transform_timeout": 0.0,
    "odom0": "example/odom",
    "odom0_config": ODOM,
    "odom0_queue_size": 2,
    "odom0_pose_rejection_threshold": 5.0,
    "imu0": "example/imu",
    "imu0_config": IMU,
    "imu0_relative": True,
    "imu0_remove_gravitational_acceleration": True,
    "pose0": "example/pose",
    "pose0_config": POSE,
    "pose0_rejection_threshold": 2.0,
    "twist0": "example/twist",
    "twist0_config": TWIST,
    "process_noise_covariance": [1e-3, 1e-3, 1e-3, 0.3, 0.3, 0.01, 0.5, 0.5, 0.1, 0.3, 0.3, 0.3, 0.3, 0.3, 0.3],
    "initial_estimate_covariance": [1e-9, 1e-9, 1e-9, 1.0, 1.0, 1e-9, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0],
    "alpha": 0.001,
}


def _yaml(value):
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float) and value and abs(value) < 0.01:
        return f"{value:.0e}".replace("e-0", "e-")  # 1e-3, 1e-9: no dot, as robot_localization writes them
    if isinstance(value, list):
        return "[" + ", ".join(_yaml(v) for v in value) + "]"
    return str(value)


def _toml(value):
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return f'"{value}"'
    if isinstance(value, list):
        return "[" + ", ".join(_toml(v) for v in value) + "]"
    return repr(value)


def _from_code(cls, tmp_path):
    return cls(parameter_overrides=VALUES)


def _from_dash_p(cls, tmp_path):
    args = ["--ros-args"]
    for name, value in VALUES.items():
        args += ["-p", f"{name}:={_yaml(value)}"]
    return cls(cli_args=args)


def _from_file(cls, tmp_path):
    name = {EkfNode: "ekf_filter_node", UkfNode: "ukf_filter_node"}[cls]
    lines = ["/**:", "  ros__parameters:", "    use_sim_time: false", f"{name}:", "  ros__parameters:"]
    lines += [f"    {key}: {_yaml(value)}" for key, value in VALUES.items()]
    path = tmp_path / "filter.yaml"
    path.write_text("\n".join(lines) + "\n")
    assert "1e-3, 1e-3, 1e-3, 0.3" in path.read_text()
    return cls(cli_args=["--ros-args", "--params-file", str(path)])


def _from_toml(cls, tmp_path):
    from aiorobot.launch import build_nodes, load_config

    table = ", ".join(f"{key} = {_toml(value)}" for key, value in VALUES.items())
    path = tmp_path / "graph.toml"
    path.write_text(f'[[nodes]]\nuse = "aiorobot.fusion:{cls.__name__}"\nparameters = {{ {table} }}\n')
    [(node, _)] = build_nodes(load_config(path))
    return node


def _summary(node):
    inputs = [
        (c.name, c.kind, c.topic, c.config.tolist(), c.queue_size, c.pose_threshold, c.twist_threshold,
         c.relative, c.remove_gravitational_acceleration)
        for c in node.inputs
    ]  # fmt: skip
    values = {name: node.get_parameter(name).value for name in VALUES}
    topics = sorted(s.topic_name for s in node.subscriptions)
    return inputs, values, topics


@pytest.mark.parametrize("cls", [EkfNode, UkfNode])
def test_code_toml_dash_p_and_a_parameter_file_build_the_same_filter(cls, tmp_path, caplog):
    results = {}
    for way in (_from_code, _from_toml, _from_dash_p, _from_file):
        caplog.clear()
        with caplog.at_level(logging.WARNING):
            node = way(cls, tmp_path)
        warnings = sorted(r.getMessage() for r in caplog.records if r.levelno == logging.WARNING)
        results[way.__name__] = (*_summary(node), warnings)
    first = results["_from_code"]
    for way, result in results.items():
        assert result == first, way
    inputs, values, topics, warnings = first
    assert [i[0] for i in inputs] == ["imu0", "odom0", "pose0", "twist0"]
    assert {"/example/odom", "/example/imu", "/example/pose", "/example/twist"} <= set(topics)
    assert values["process_noise_covariance"][:4] == [1e-3, 1e-3, 1e-3, 0.3]
    assert "robot_localization parameter 'debug' has no effect in aiorobot" in warnings
    assert "robot_localization parameter 'transform_timeout' has no effect in aiorobot" in warnings
    alpha = [w for w in warnings if w.startswith("'alpha'")]
    if cls is EkfNode:
        assert alpha == ["'alpha' is UkfNode's (robot_localization's ukf_node) parameter; it has no effect in EkfNode"]
    else:
        assert alpha == []


def test_an_unknown_name_from_a_file_names_the_file_and_key(tmp_path):
    path = tmp_path / "ekf.yaml"
    path.write_text("ekf_filter_node:\n  ros__parameters:\n    odom0: /odom\n    odom0_cofnig: [true]\n")
    with pytest.raises(ValueError) as info:
        EkfNode(cli_args=["--ros-args", "--params-file", str(path)])
    assert str(info.value) == (
        f'unknown robot_localization parameter "odom0_cofnig" (from {path}: '
        '/ekf_filter_node.ros__parameters.odom0_cofnig (line 4)); did you mean "odom0_config"?'
    )


def test_a_generic_node_reads_file_and_dash_p_values_like_code_values(tmp_path):
    # every node, not only the filters: a file value and a -p value meet the declaration as a code value does
    path = tmp_path / "p.yaml"
    path.write_text("/**:\n  ros__parameters:\n    gains: [1e-3, 0.3]\n    rate: 1e2\n")
    by_file = Node("n", cli_args=["--ros-args", "--params-file", str(path)])
    by_dash_p = Node("n", cli_args=["--ros-args", "-p", "gains:=[1e-3, 0.3]", "-p", "rate:=1e2"])
    by_code = Node("n", parameter_overrides={"gains": [1e-3, 0.3], "rate": 100.0})
    for node in (by_file, by_dash_p, by_code):
        assert node.declare_parameter("gains", [0.0]).value == [1e-3, 0.3]
        assert node.declare_parameter("rate", 1.0).value == 100.0
        assert node.get_parameter_overrides() == {"gains": [1e-3, 0.3], "rate": 100.0}


def test_aiorobot_run_with_a_parameter_file_says_what_it_fuses_and_what_has_no_effect(tmp_path):
    import os
    import subprocess
    import sys

    path = tmp_path / "ukf.yaml"
    path.write_text(
        "ukf_filter_node:\n  ros__parameters:\n    debug: false\n    odom0: example/odom\n"
        f"    odom0_config: {_yaml(ODOM)}\n    initial_estimate_covariance: {_yaml([1e-9] * 15)}\n"
        "    alpha: 0.001\n    kappa: 0.0\n    beta: 2.0\n"
    )
    env = {k: v for k, v in os.environ.items() if k != "PYTHONWARNINGS"}
    done = subprocess.run(
        [sys.executable, "-m", "aiorobot.cli", "run", "aiorobot.fusion:UkfNode", "--duration", "0.1",
         "--ros-args", "--params-file", str(path)],
        capture_output=True, text=True, timeout=120, env=env,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert "[/ukf_filter_node]: robot_localization parameter 'debug' has no effect in aiorobot" in done.stderr
    assert "[/ukf_filter_node]: fusing odom0 (odom on example/odom)" in done.stderr
    assert "Traceback" not in done.stderr and "alpha" not in done.stderr


def test_a_filter_without_inputs_says_so(caplog):
    with caplog.at_level(logging.WARNING):
        EkfNode(parameter_overrides={"frequency": 10.0})
    assert "no input given (odom0, imu0, pose0, twist0, ...): the filter has nothing to fuse" in caplog.text
