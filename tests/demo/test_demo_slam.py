"""``aiorobot demo --slam``: no map given; SLAM builds it while the robot drives, the planner plans on it."""

from __future__ import annotations

import math

import pytest

from aiorobot.cli import main
from aiorobot.demo import run_demo
from aiorobot.demo._graph import WORLD_MAP_TOPIC, build_graph
from aiorobot.sim import World

pytestmark = pytest.mark.timeout(300)


def test_the_slam_graph_moves_the_world_map_aside_and_starts_the_map_at_the_robot() -> None:
    graph = build_graph(World.load("box"), rtf=0.0, seed=3, drive="direct", localisation="slam", perception=False,
                        start=(0.5, -0.5, 0.25))
    names = [node.get_fully_qualified_name() for node, _ in graph.nodes]
    assert names == ["/simulator", "/local/ekf_local", "/slam_toolbox", "/navigation_server", "/collision_monitor"]
    assert graph.simulator.map_pub.topic_name == WORLD_MAP_TOPIC  # /map is SLAM's alone
    assert list(graph.slam.get_parameter("map_start_pose").value) == [0.5, -0.5, 0.25]


async def test_a_mission_in_the_box_on_a_map_slam_builds_as_it_goes() -> None:
    from test_demo_kernels import signatures  # tests/demo is on sys.path (no package)

    build_graph(World.load("box"), rtf=0.0, seed=3, drive="direct", localisation="slam", perception=False)
    built = signatures()
    assert {"aiorobot.nav._slam_kernels.search", "aiorobot.nav._slam_kernels.refine"} <= set(built)
    summary = await run_demo("box", [(1.5, -1.5, math.pi / 2), (1.5, 1.5, math.pi), (-1.5, 1.5, -math.pi / 2)],
                             seed=3, localisation="slam", perception=False, timeout_sim_sec=120.0)
    f = summary.figures()
    assert summary.succeeded, f
    assert summary.localisation_rmse_m < 0.05  # map -> base_link from SLAM against ground truth
    assert f["slam_nodes"] >= 10 and f["slam_map_precision"] >= 0.95 and f["slam_map_recall"] >= 0.8
    assert summary.slam_map is not None and "slam_map" not in f
    after = signatures()
    grown = {name: after[name] - built.get(name, set()) for name in after if after[name] - built.get(name, set())}
    assert grown == {}, f"compiled inside a callback, not at construction: {grown}"


def test_slam_with_another_localisation_is_refused_in_one_line(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["demo", "--slam", "--localisation", "landmarks"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["aiorobot demo: error: --slam localises on the map it builds: leave out --localisation landmarks"]
