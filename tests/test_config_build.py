"""The building half of the config loader: importing node classes and constructing nodes."""

from __future__ import annotations

import logging
import re
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from aiorobot import Node
from aiorobot.launch import ConfigError, build_nodes, load_config

BUILD_CONFIGS = Path(__file__).parent / "configs" / "build"
BAD_BUILD = sorted(BUILD_CONFIGS.glob("*.toml"))
FIXTURE_MODULES = ("config_test_nodes", "broken_import")


def expected_message(path: Path) -> str:
    first = path.read_text(encoding="utf-8").splitlines()[0]
    assert first.startswith("# expect: "), f"{path} must start with '# expect: '"
    text = first.removeprefix("# expect: ").replace("{dir}", str(path.parent.resolve()))
    return f"{path}: {text}"


@pytest.fixture(autouse=True)
def isolated_imports(monkeypatch: pytest.MonkeyPatch) -> Iterator[None]:
    """build_nodes puts the config's folder on sys.path and imports from it: undo both."""
    monkeypatch.setattr(sys, "path", list(sys.path))
    before = set(sys.modules)
    yield
    for name in set(sys.modules) - before:
        if name.startswith(("user_", *FIXTURE_MODULES)):
            del sys.modules[name]


def write_graph(folder: Path, toml: str, modules: dict[str, str] | None = None) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    for name, source in (modules or {}).items():
        (folder / f"{name}.py").write_text(source, encoding="utf-8")
    path = folder / "graph.toml"
    path.write_text(toml, encoding="utf-8")
    return path


USER_NODES = '''
from aiorobot import Node

class Talker(Node):
    def __init__(self, **kw):
        super().__init__("talker", **kw)
        self.rate_hz = self.declare_parameter("rate_hz", 10.0, range=(1.0, 100.0)).value
        self.gains = self.declare_parameter("pid.gains", [1.0, 0.0]).value
        self.pub = self.create_publisher(__import__("aiorobot.msgs.std_msgs", fromlist=["String"]).String, "chatter", 10)
'''


@pytest.mark.parametrize("path", BAD_BUILD, ids=lambda p: p.stem)
def test_bad_node_table_raises_one_line_error_before_anything_starts(path: Path) -> None:
    config = load_config(path)
    with pytest.raises(ConfigError, match=rf"^{re.escape(expected_message(path))}$") as info:
        build_nodes(config)
    assert "\n" not in str(info.value)


def test_builds_user_nodes_from_the_config_folder_in_file_order(tmp_path: Path) -> None:
    toml = """
[[nodes]]
use = "user_talkers:Talker"
parameters = { rate_hz = 20, pid = { gains = [2.0, 0.5] } }

[[nodes]]
name = "loud"
namespace = "/robot"
use = "user_talkers:Talker"
executor = "priority"
remap = { chatter = "/shout" }
"""
    path = write_graph(tmp_path / "graph", toml, {"user_talkers": USER_NODES})
    built = build_nodes(load_config(path))
    (first, first_executor), (second, second_executor) = built
    assert (first_executor, second_executor) == ("main", "priority")
    assert all(isinstance(node, Node) for node, _ in built)
    assert type(first).__module__ == "user_talkers"
    assert first.get_fully_qualified_name() == "/talker"
    assert (second.get_name(), second.get_namespace()) == ("loud", "/robot")
    assert second.get_fully_qualified_name() == "/robot/loud"
    assert first.rate_hz == 20.0 and first.get_parameter("rate_hz").value == 20.0
    assert first.get_parameter("pid.gains").value == [2.0, 0.5]
    assert second.get_parameter("rate_hz").value == 10.0, "defaults stay when not overridden"
    assert first.pub.topic_name == "/chatter"
    assert second.pub.topic_name == "/shout", "remap applies"


def test_config_folder_comes_first_on_sys_path(tmp_path: Path) -> None:
    path = write_graph(tmp_path / "g", '[[nodes]]\nuse = "user_first:Talker"\n', {"user_first": USER_NODES})
    build_nodes(load_config(path))
    assert sys.path[0] == str((tmp_path / "g").resolve())


def test_syntax_error_in_user_module_names_file_and_line(tmp_path: Path) -> None:
    path = write_graph(
        tmp_path / "s", '[[nodes]]\nuse = "user_syntax:Talker"\n', {"user_syntax": "def oops(:\n    pass\n"}
    )
    with pytest.raises(
        ConfigError,
        match=r'^.*graph\.toml: nodes\[0\]\.use: importing module "user_syntax" failed: SyntaxError: '
        r"invalid syntax \(user_syntax\.py, line 1\)$",
    ):
        build_nodes(load_config(path))


def test_error_raised_while_importing_user_module_is_reported(tmp_path: Path) -> None:
    path = write_graph(
        tmp_path / "r",
        '[[nodes]]\nuse = "user_raises:Talker"\n',
        {"user_raises": "raise ImportError('needs the vendor SDK: pip install acme-sdk')\n"},
    )
    with pytest.raises(
        ConfigError,
        match=r'^.*: nodes\[0\]\.use: importing module "user_raises" failed: ImportError: needs the '
        r"vendor SDK: pip install acme-sdk$",
    ):
        build_nodes(load_config(path))


def test_per_node_log_level_is_applied(tmp_path: Path) -> None:
    toml = '[[nodes]]\nuse = "user_logs:Talker"\nlog_level = "debug"\n[[nodes]]\nname = "quiet"\nuse = "user_logs:Talker"\nlog_level = "error"\n'
    path = write_graph(tmp_path / "l", toml, {"user_logs": USER_NODES})
    (loud, _), (quiet, _) = build_nodes(load_config(path))
    assert loud.get_logger().get_effective_level() == logging.DEBUG
    assert quiet.get_logger().get_effective_level() == logging.ERROR


def test_nested_class_path_is_followed(tmp_path: Path) -> None:
    source = USER_NODES + "\nclass Robots:\n    Talker = Talker\n"
    path = write_graph(tmp_path / "n", '[[nodes]]\nuse = "user_nested:Robots.Talker"\n', {"user_nested": source})
    ((node, _),) = build_nodes(load_config(path))
    assert type(node).__name__ == "Talker"
