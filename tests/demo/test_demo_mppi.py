"""The demo with ``--controller mppi``: the whole simulated robot follows its mission with MPPI."""

from __future__ import annotations

import math

import pytest

from aiorobot.cli import main
from aiorobot.demo import run_demo
from aiorobot.demo._graph import build_graph
from aiorobot.sim import World

pytestmark = pytest.mark.timeout(300)


async def test_a_box_mission_with_mppi_reaches_its_waypoints_without_collision() -> None:
    summary = await run_demo("box", [(1.5, 0.0, math.pi / 2)], seed=3, timeout_sim_sec=60.0,
                             perception=False, controller="mppi")
    assert summary.controller == "mppi" and summary.figures()["controller"] == "mppi"
    assert summary.waypoints_reached == 1 and summary.collisions == 0, summary.figures()
    assert summary.succeeded and not summary.failures


def test_the_controller_option_reaches_the_navigation_server_and_a_bad_one_is_refused(capsys) -> None:
    graph = build_graph(World.load("box"), rtf=0.0, seed=1, drive="direct", localisation="amcl", perception=False,
                        controller="mppi")
    try:
        assert graph.server.controller == "mppi" and graph.server.mppi_params.batch_size == 1000
    finally:
        for node, _ in graph.nodes:
            node.destroy_node()
    with pytest.raises(ValueError, match=r"^controller: expected one of rpp, mppi, found 'dwb'$"):
        build_graph(World.load("box"), rtf=0.0, seed=1, drive="direct", localisation="amcl", perception=False,
                    controller="dwb")
    assert main(["demo", "--world", "box", "--controller", "dwb"]) == 2
    assert "argument --controller: invalid choice: 'dwb' (choose from 'rpp', 'mppi')" in capsys.readouterr().err
