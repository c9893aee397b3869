"""``aiorobot param`` against a node in another process, through its rcl_interfaces services."""

from __future__ import annotations

from collections.abc import Iterator

import pytest
import yaml

from ._graph_process import GraphProcess, run_cli, start_graph

GRAPH = """
async def main(rt):
    node = rt.add_node(Node("driver", namespace="/robot"))
    node.declare_parameter("rate_hz", 20, description="publish rate", range=(1, 100))
    node.declare_parameter("gain", 0.5)
    node.declare_parameter("frame", "base_link", read_only=True)
    node.declare_parameter("enabled", True)
    node.declare_parameter("pid.kp", 1.5)
    node.declare_parameter("pid.ids", [1, 2, 3])
    node.add_post_set_parameters_callback(lambda ps: say("set", *(f"{p.name}={p.value!r}" for p in ps)))
    say("ready")
    await asyncio.Event().wait()
"""


@pytest.fixture(scope="module")
def graph() -> Iterator[GraphProcess]:
    yield from start_graph(GRAPH)


def test_list_get_and_describe(graph: GraphProcess) -> None:
    code, out, err = run_cli(graph, "param", "list", "/robot/driver", "--param-type")
    assert code == 0, err
    assert out.splitlines() == [
        "  enabled (type: boolean)",
        "  frame (type: string)",
        "  gain (type: double)",
        "  pid.ids (type: integer array)",
        "  pid.kp (type: double)",
        "  rate_hz (type: integer)",
        "  use_sim_time (type: boolean)",
    ]
    code, out, err = run_cli(graph, "param", "list")
    assert code == 0, err
    assert out.splitlines()[0] == "/robot/driver:" and "  rate_hz" in out.splitlines()

    code, out, err = run_cli(graph, "param", "get", "/robot/driver", "pid.ids")
    assert (code, out) == (0, "Integer values are: [1, 2, 3]\n"), err

    code, out, err = run_cli(graph, "param", "describe", "robot/driver", "rate_hz", "frame")
    assert code == 0, err
    assert out.splitlines() == [
        "Parameter name: rate_hz",
        "  Type: integer",
        "  Description: publish rate",
        "  Constraints:",
        "    Min value: 1",
        "    Max value: 100",
        "Parameter name: frame",
        "  Type: string",
        "  Constraints:",
        "    Read only: true",
    ]


def test_set_parses_the_value_as_yaml_and_the_node_sees_it(graph: GraphProcess) -> None:
    code, out, err = run_cli(graph, "param", "set", "/robot/driver", "gain", "2.25")
    assert (code, out) == (0, "Set parameter successful\n"), err
    assert graph.expect("set") == "set gain=2.25"
    code, out, err = run_cli(graph, "param", "get", "/robot/driver", "gain", "--hide-type")
    assert (code, out) == (0, "2.25\n"), err


def test_dump_writes_a_parameter_file_that_load_reads_back(graph: GraphProcess, tmp_path) -> None:  # type: ignore[no-untyped-def]
    code, out, err = run_cli(graph, "param", "dump", "/robot/driver", "--output-dir", str(tmp_path))
    assert code == 0, err
    path = tmp_path / "robot__driver.yaml"
    assert out == f"Saving to:  {path}\n"
    dumped = yaml.safe_load(path.read_text())
    params = dumped["/robot/driver"]["ros__parameters"]
    assert params["pid"] == {"ids": [1, 2, 3], "kp": 1.5} and params["rate_hz"] == 20

    params["rate_hz"] = 42
    params["pid"]["kp"] = 3.0
    del params["frame"]  # read-only: setting it, even to its value, fails
    path.write_text(yaml.safe_dump(dumped))
    code, out, err = run_cli(graph, "param", "load", "/robot/driver", str(path))
    assert code == 0, err
    assert "Set parameter rate_hz successful" in out.splitlines() and "Set parameter pid.kp successful" in out.splitlines()
    code, out, err = run_cli(graph, "param", "get", "/robot/driver", "rate_hz")
    assert (code, out) == (0, "Integer value is: 42\n"), err


def test_bad_input_gives_one_line_and_a_failure_status(graph: GraphProcess, tmp_path) -> None:  # type: ignore[no-untyped-def]
    code, out, err = run_cli(graph, "param", "get", "/nobody", "gain")
    assert code == 1
    assert err.splitlines() == ["aiorobot param get: error: unknown node '/nobody'; 'aiorobot node list' shows the nodes"]

    code, out, err = run_cli(graph, "param", "set", "/robot/driver", "rate_hz", "fast")
    assert code == 1 and len(err.splitlines()) == 1, err
    assert err.startswith("aiorobot param set: error: setting rate_hz on /robot/driver to 'fast' failed: ")
    assert "integer" in err and "string" in err

    code, out, err = run_cli(graph, "param", "set", "/robot/driver", "rate_hz", "500")
    assert code == 1 and "rate_hz" in err and len(err.splitlines()) == 1, err

    code, out, err = run_cli(graph, "param", "get", "/robot/driver", "nope")
    assert code == 1 and err.splitlines() == [
        "aiorobot param get: error: parameter 'nope' is not declared on /robot/driver; "
        "'aiorobot param list /robot/driver' shows its parameters"
    ]

    bad = tmp_path / "bad.yaml"
    bad.write_text("/robot/driver:\n  ros__parameters: {gain: [1, 2\n")
    code, out, err = run_cli(graph, "param", "load", "/robot/driver", str(bad))
    assert code == 1 and len(err.splitlines()) == 1 and err.startswith(f"aiorobot param load: error: {bad}: not valid YAML")

    code, out, err = run_cli(graph, "param", "set", "/robot/driver")
    assert code == 2 and "Traceback" not in err
