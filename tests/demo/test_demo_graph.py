"""The demo's graph ships as a TOML (aiorobot/demo/graph.toml); its EKFs are the dual set-up
that examples/fusion_ekf.toml shares (aiorobot/demo/dual_ekf.yaml)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from aiorobot import load_config
from aiorobot.demo._graph import GRAPH_FILE, ROBOT_RADIUS, build_graph
from aiorobot.sim import World

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "fusion_ekf.toml"


def _layout(graph) -> list[tuple[str, str]]:
    return [(node.get_fully_qualified_name(), executor) for node, executor in graph.nodes]


@pytest.mark.parametrize(
    ("localisation", "perception", "expected"),
    [
        ("amcl", True, [("/simulator", "main"), ("/local/ekf_local", "priority"), ("/amcl", "main"),
                        ("/aruco", "main"), ("/scan_obstacles", "main"), ("/navigation_server", "main"), ("/collision_monitor", "priority")]),
        ("amcl", False, [("/simulator", "main"), ("/local/ekf_local", "priority"), ("/amcl", "main"),
                         ("/navigation_server", "main"), ("/collision_monitor", "priority")]),
        ("landmarks", True, [("/simulator", "main"), ("/local/ekf_local", "priority"), ("/landmark_fixes", "main"),
                             ("/global/ekf_global", "priority"), ("/aruco", "main"), ("/scan_obstacles", "main"),
                             ("/navigation_server", "main"), ("/collision_monitor", "priority")]),
    ],
)
def test_the_options_pick_the_graph_files_nodes_and_add_the_runs_parameters(localisation, perception, expected) -> None:
    world = World.load("box")
    graph = build_graph(world, rtf=0.0, seed=3, drive="direct", localisation=localisation, perception=perception,
                        start=(0.5, -0.5, 0.25))
    assert _layout(graph) == expected
    assert graph.control_node is graph.ekf_local and graph.server.get_name() == "navigation_server"
    # the controller's commands go through the collision monitor to the base
    assert graph.server.cmd_pub.topic_name == "/cmd_vel_nav" and graph.collision_monitor.cmd_pub.topic_name == "/cmd_vel"
    sim = graph.simulator
    assert sim.get_parameter("world").value == str(world.path) and sim.get_parameter("seed").value == 3
    # a rectangular base inside the disc the navigation server and the start checks use
    assert sim.body.footprint is not None and np.hypot(*sim.body.footprint.T).max() <= ROBOT_RADIUS
    assert sim.get_parameter("camera_rate").value == (15.0 if perception else 0.0)
    if localisation == "landmarks":
        ekf_global = graph.nodes[3][0]
        assert list(ekf_global.get_parameter("initial_state").value[:6]) == [0.5, -0.5, 0.0, 0.0, 0.0, 0.25]
        assert graph.landmark_fixes.landmark_map.path.endswith("box.landmarks.yaml")
    else:
        amcl = graph.nodes[2][0]
        assert (amcl.get_parameter("initial_pose.x").value, amcl.get_parameter("min_particles").value) == (0.5, 300)


def test_the_graph_file_is_an_aiorobot_run_config_naming_every_node() -> None:
    config = load_config(GRAPH_FILE)
    assert [n.name for n in config.nodes] == [
        "simulator", "serial_motor_bridge", "mecanum_controller", "ekf_local", "amcl", "landmark_fixes", "ekf_global",
        "slam_toolbox", "aruco", "scan_obstacles", "navigation_server", "collision_monitor"]


def test_the_example_and_the_demo_run_one_definition_of_the_dual_ekf() -> None:
    from aiorobot.launch import build_nodes

    shared = ("odom0", "odom0_config", "imu0", "imu0_config", "process_noise_covariance", "world_frame", "pose0",
              "pose0_config", "pose0_rejection_threshold")
    example = {n.get_fully_qualified_name(): n for n, _ in build_nodes(load_config(EXAMPLE))}
    demo = build_graph(World.load("box"), rtf=0.0, seed=1, drive="direct", localisation="landmarks", perception=True)
    ours = {n.get_fully_qualified_name(): n for n, _ in demo.nodes}
    for fqn in ("/local/ekf_local", "/global/ekf_global"):
        names = [name for name in shared if ours[fqn].has_parameter(name)]
        assert _values(example[fqn], names) == _values(ours[fqn], names), fqn
        # the example's own inline choices override the shared file
        assert example[fqn].get_parameter("frequency").value == 30.0 and ours[fqn].get_parameter("frequency").value == 50.0
    assert ours["/global/ekf_global"].get_parameter("pose0").value == "/landmark_pose"


def _values(node, names: list[str]) -> dict[str, object]:
    out: dict[str, object] = {}
    for name in names:
        value = node.get_parameter(name).value
        out[name] = list(value) if not isinstance(value, (str, bool, int, float)) else value
    return out
