"""``aiorobot lifecycle`` against lifecycle nodes in another process, through their lifecycle_msgs services."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from ._graph_process import GraphProcess, run_cli, start_graph

GRAPH = """
from aiorobot.lifecycle import LifecycleNode, TransitionCallbackReturn

class Camera(LifecycleNode):
    async def on_configure(self, state):
        say("configured", self.get_fully_qualified_name())
        return TransitionCallbackReturn.SUCCESS

class Picky(LifecycleNode):
    async def on_configure(self, state):
        return TransitionCallbackReturn.FAILURE

async def main(rt):
    rt.add_node(Camera("camera", namespace="/robot"))
    rt.add_node(Picky("picky"))
    rt.add_node(Node("plain"))
    say("ready")
    await asyncio.Event().wait()
"""


@pytest.fixture(scope="module")
def graph() -> Iterator[GraphProcess]:
    yield from start_graph(GRAPH)


def test_nodes_get_list_and_set(graph: GraphProcess) -> None:
    code, out, err = run_cli(graph, "lifecycle", "nodes")
    assert (code, out) == (0, "/picky\n/robot/camera\n"), err

    code, out, err = run_cli(graph, "lifecycle", "get", "/robot/camera")
    assert (code, out) == (0, "unconfigured [1]\n"), err

    code, out, err = run_cli(graph, "lifecycle", "list", "/robot/camera")
    assert code == 0, err
    assert out.splitlines() == [
        "- configure [1]", "\tStart: unconfigured", "\tGoal: configuring",
        "- shutdown [5]", "\tStart: unconfigured", "\tGoal: shuttingdown",
    ]

    code, out, err = run_cli(graph, "lifecycle", "set", "/robot/camera", "configure")
    assert (code, out) == (0, "Transitioning successful\n"), err
    assert graph.expect("configured") == "configured /robot/camera"

    code, out, err = run_cli(graph, "lifecycle", "set", "robot/camera", "3")  # activate, by id
    assert (code, out) == (0, "Transitioning successful\n"), err

    code, out, err = run_cli(graph, "lifecycle", "get")
    assert (code, out) == (0, "/picky: unconfigured [1]\n/robot/camera: active [3]\n"), err


def test_refused_and_unknown_transitions_and_nodes_fail_with_one_line(graph: GraphProcess) -> None:
    code, out, err = run_cli(graph, "lifecycle", "set", "/picky", "configure")
    assert code == 1 and err.splitlines() == ["aiorobot lifecycle set: error: transitioning /picky with configure failed"]

    code, out, err = run_cli(graph, "lifecycle", "set", "/picky", "activate")
    assert code == 1 and err.splitlines() == [
        "aiorobot lifecycle set: error: transition 'activate' is not available from /picky's current state; "
        "available: configure [1], shutdown [5]"
    ]

    code, out, err = run_cli(graph, "lifecycle", "get", "/plain")
    assert code == 1 and err.splitlines() == [
        "aiorobot lifecycle get: error: unknown lifecycle node '/plain'; 'aiorobot lifecycle nodes' shows them"
    ]
