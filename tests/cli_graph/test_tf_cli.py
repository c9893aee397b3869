"""``aiorobot tf echo|tree`` against /tf and /tf_static published by another process."""

from __future__ import annotations

import os
import subprocess
import sys
from collections.abc import Iterator

import pytest

from ._graph_process import GraphProcess, run_cli, start_graph

GRAPH = """
from aiorobot.msgs.geometry_msgs import TransformStamped
from aiorobot.tf import StaticTransformBroadcaster, TransformBroadcaster, quaternion_from_euler

def tf(node, parent, child, xyz, yaw):
    t = TransformStamped()
    t.header.stamp = node.get_clock().now().to_msg()
    t.header.frame_id, t.child_frame_id = parent, child
    t.transform.translation.x, t.transform.translation.y, t.transform.translation.z = xyz
    q = quaternion_from_euler(0.0, 0.0, yaw)
    t.transform.rotation.x, t.transform.rotation.y, t.transform.rotation.z, t.transform.rotation.w = q
    return t

async def main(rt):
    node = rt.add_node(Node("tf_pub"))
    static = StaticTransformBroadcaster(node)
    static.send_transform([tf(node, "map", "odom", (1.0, 2.0, 0.0), 0.0),
                           tf(node, "base_link", "laser", (0.2, 0.0, 0.1), 0.0)])
    dynamic = TransformBroadcaster(node)
    say("ready")
    while True:
        dynamic.send_transform(tf(node, "odom", "base_link", (0.5, 0.0, 0.0), 1.5707963267948966))
        await asyncio.sleep(0.02)
"""


@pytest.fixture(scope="module")
def graph() -> Iterator[GraphProcess]:
    yield from start_graph(GRAPH)


def test_echo_prints_tf2_echo_blocks_through_static_and_dynamic_links(graph: GraphProcess) -> None:
    code, out, err = run_cli(graph, "tf", "echo", "map", "laser", "--count", "2", "--rate", "50")
    assert code == 0, err
    blocks = out.split("At time ")
    assert blocks[0] == "" and len(blocks) == 3
    # laser in map: map->odom (1, 2), odom->base_link (0.5, 0) yawed 90 degrees, base_link->laser (0.2, 0, 0.1)
    assert blocks[1].splitlines()[1:] == [
        "- Translation: [1.500, 2.200, 0.100]",
        "- Rotation: in Quaternion (xyzw) [0.000, 0.000, 0.707, 0.707]",
        "- Rotation: in RPY (radian) [0.000, -0.000, 1.571]",
        "- Rotation: in RPY (degree) [0.000, -0.000, 90.000]",
        "- Matrix:",
        "   0.000 -1.000  0.000  1.500",
        "   1.000  0.000  0.000  2.200",
        "   0.000  0.000  1.000  0.100",
        "   0.000  0.000  0.000  1.000",
    ]


def test_tree_shows_the_frames_as_text_and_graphviz(graph: GraphProcess) -> None:
    code, out, err = run_cli(graph, "tf", "tree", "--wait-time", "0.5")
    assert code == 0, err
    lines = out.splitlines()
    assert lines[0] == "map" and lines[1] == "  odom [static]" and lines[3] == "      laser [static]"
    assert lines[2].startswith("    base_link [") and lines[2].endswith(" Hz]")

    code, out, err = run_cli(graph, "tf", "tree", "--wait-time", "0.5", "--dot")
    assert code == 0, err
    assert out.startswith("digraph G {") and '"map" -> "odom" [label="Broadcaster: default_authority\\nstatic"];' in out
    assert '"odom" -> "base_link" [label="Broadcaster: default_authority\\nAverage rate: ' in out


def test_unknown_frames_and_bad_rates_fail_with_one_line(graph: GraphProcess) -> None:
    code, out, err = run_cli(graph, "tf", "echo", "map", "gripper", "--timeout", "0.3")
    assert code == 1 and len(err.splitlines()) == 1, err
    assert err.startswith("aiorobot tf echo: error: no transform from 'map' to 'gripper': ")
    assert err.rstrip().endswith("(frames received: base_link, laser, map, odom)")

    code, out, err = run_cli(graph, "tf", "echo", "map", "odom", "--rate", "0")
    assert code == 2 and err.splitlines() == [
        "aiorobot tf echo: error: --rate: expected a positive number of echoes per second, found 0.0"
    ]


def test_a_reader_that_goes_away_ends_the_command_quietly(graph: GraphProcess) -> None:
    # `aiorobot tf echo map laser | head -1`: the pipe closes under the command, as `cat` it ends with
    # SIGPIPE's status and no traceback.
    read_end, write_end = os.pipe()
    os.close(read_end)
    try:
        proc = subprocess.run(
            [sys.executable, "-m", "aiorobot.cli", "tf", "echo", "map", "laser", "--count", "3", "--rate", "50",
             "--connect", f"tcp/127.0.0.1:{graph.port}"],
            stdout=write_end, stderr=subprocess.PIPE, text=True, timeout=30,
        )
    finally:
        os.close(write_end)
    assert proc.returncode == 141 and proc.stderr == "", proc.stderr
