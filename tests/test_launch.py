"""aiorobot.launch opens a Runtime from a graph file; the core reads no config file and never imports launch."""

from __future__ import annotations

import inspect
import subprocess
import sys
from pathlib import Path

import pytest

import aiorobot
from aiorobot.launch import ConfigError, RuntimeConfig, load_config, open_runtime, runtime_options

GRAPH = """\
[runtime]
domain_id = 7

[[nodes]]
use = "aiorobot.examples.sensor:ImuPublisher"
name = "imu_a"
parameters = { rate_hz = 20.0 }
"""


def write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "graph.toml"
    path.write_text(text, encoding="utf-8")
    return path


async def test_open_runtime_takes_the_runtime_table_and_builds_the_nodes_on_entry(tmp_path):
    rt = open_runtime(write(tmp_path, GRAPH), handle_signals=False)
    assert rt.domain_id == 7 and rt.nodes == ()  # nothing is imported or built before entry
    async with rt:
        [node] = rt.nodes
        assert node.get_fully_qualified_name() == "/imu_a"
        assert node.get_parameter("rate_hz").value == 20.0


async def test_runtime_config_keyword_still_builds_the_graph(tmp_path):
    """API.md's ``Runtime(config=...)``: a path or a loaded GraphConfig, through the loader launch installs."""
    path = write(tmp_path, GRAPH)
    for config in (path, load_config(path)):
        async with aiorobot.Runtime(config=config, handle_signals=False) as rt:
            assert rt.domain_id == 7
            assert [n.get_name() for n in rt.nodes] == ["imu_a"]


async def test_a_node_that_cannot_be_built_fails_the_entry_and_starts_nothing(tmp_path):
    path = write(tmp_path, GRAPH.replace("ImuPublisher", "ImuPublsher"))
    rt = open_runtime(path, handle_signals=False)  # the file itself is valid
    with pytest.raises(ConfigError, match=r'nodes\[0\]\.use: module "aiorobot.examples.sensor" has no class "ImuPublsher"'):
        async with rt:
            pass
    assert rt.nodes == ()


def test_open_runtime_refuses_an_argument_the_file_sets(tmp_path):
    path = write(tmp_path, GRAPH)
    for name, value in runtime_options(load_config(path)).items():
        with pytest.raises(TypeError, match=rf"^open_runtime: {name} is set by the \[runtime\] table of "):
            open_runtime(path, **{name: value})
    with pytest.raises(TypeError, match=r"^config: expected a graph file path or a GraphConfig, found 3$"):
        open_runtime(3)  # type: ignore[arg-type]


def test_a_file_without_a_runtime_table_gets_the_runtimes_own_defaults(tmp_path):
    options = runtime_options(load_config(write(tmp_path, GRAPH.replace("domain_id = 7\n", ""))))
    defaults = {n: p.default for n, p in inspect.signature(aiorobot.Runtime).parameters.items()}
    assert options == {name: defaults[name] for name in options}
    fields = RuntimeConfig()
    for name in ("domain_id", "shutdown_timeout", "stall_threshold", "priority_stall_threshold", "late_threshold"):
        assert getattr(fields, name) == defaults[name], name


def test_late_threshold_is_set_in_the_file_or_turned_off_with_false(tmp_path):
    from aiorobot.launch import ConfigError

    for text, expected in (("late_threshold = 0.005", 0.005), ("late_threshold = false", None)):
        path = write(tmp_path, GRAPH.replace("domain_id = 7\n", f"domain_id = 7\n{text}\n"))
        assert runtime_options(load_config(path))["late_threshold"] == expected
    path = write(tmp_path, GRAPH.replace("domain_id = 7\n", "domain_id = 7\nlate_threshold = 0\n"))
    with pytest.raises(ConfigError, match=r"runtime\.late_threshold: expected a number of seconds > 0 or false, found 0$"):
        load_config(path)


def test_the_core_and_the_transports_import_no_launch_module_and_runtime_says_what_to_call_instead():
    code = (
        "import importlib, pkgutil, sys, aiorobot\n"
        "def load(path, prefix):\n"  # every core module: aiorobot._x, and aiorobot._x.y below a _x package
        "    for info in pkgutil.iter_modules(path, prefix):\n"
        "        if info.name.split('.')[1].startswith('_'):\n"
        "            module = importlib.import_module(info.name)\n"
        "            if info.ispkg:\n"
        "                load(module.__path__, info.name + '.')\n"
        "load(aiorobot.__path__, 'aiorobot.')\n"
        "import aiorobot.transport\n"  # a transport's config errors are ConfigErrors too, from the core
        "loaded = sorted(m for m in sys.modules if m.startswith(('aiorobot.launch', 'aiorobot.bag', 'aiorobot.foxglove')))\n"
        "assert loaded == [], loaded\n"
        "from aiorobot._core._runtime import Runtime\n"
        "try:\n"
        "    Runtime(config='graph.toml')\n"
        "except TypeError as err:\n"
        "    print(err)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], check=True, capture_output=True, text=True, timeout=60)
    assert "use aiorobot.launch.open_runtime(config)" in out.stdout


def test_the_package_root_keeps_the_config_names():
    import aiorobot.launch

    assert aiorobot.load_config is aiorobot.launch.load_config
    assert aiorobot.ConfigError is aiorobot.launch.ConfigError
    assert aiorobot.GraphConfig is aiorobot.launch.GraphConfig
    from aiorobot.transport import ZenohConfigError

    assert issubclass(ZenohConfigError, aiorobot.ConfigError)
