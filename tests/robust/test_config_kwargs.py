"""The config builder refuses a node class whose constructor drops ``**kwargs``."""

from __future__ import annotations

import textwrap

import pytest

from aiorobot.launch import ConfigError, build_nodes, load_config

NODES = textwrap.dedent(
    '''
    from aiorobot import Node

    class Dropper(Node):
        def __init__(self, **kw):
            super().__init__("fixed_name")
            self.declare_parameter("speed", 1.0)

    class Keeper(Node):
        def __init__(self, **kw):
            super().__init__("fixed_name", **kw)
            self.declare_parameter("speed", 1.0)
    '''
)


@pytest.mark.parametrize(
    "table, dropped",
    [
        ('name = "robot"', "name 'robot' (the node is named 'fixed_name')"),
        ('namespace = "/base"', "namespace '/base' (the node has '/')"),
        ("parameters = { speed = 2.0 }", "parameters"),
        ('remap = { "/a" = "/b" }', "remap"),
    ],
)
def test_a_constructor_that_drops_kwargs_is_refused_in_one_line(tmp_path, monkeypatch, table, dropped):
    (tmp_path / "dropping_nodes.py").write_text(NODES)
    path = tmp_path / "g.toml"
    path.write_text(f'[[nodes]]\nuse = "dropping_nodes:Dropper"\n{table}\n')
    monkeypatch.syspath_prepend(str(tmp_path))
    with pytest.raises(ConfigError) as err:
        build_nodes(load_config(path))
    assert str(err.value) == (
        f"{path}: nodes[0]: Dropper ignored its configured {dropped}: its constructor must pass **kwargs "
        'to Node.__init__ (write "def __init__(self, **kw): super().__init__("name", **kw)")'
    )


def test_a_constructor_that_passes_kwargs_is_built_as_configured(tmp_path, monkeypatch):
    (tmp_path / "keeping_nodes.py").write_text(NODES)
    path = tmp_path / "g.toml"
    path.write_text(
        '[[nodes]]\nuse = "keeping_nodes:Keeper"\nname = "robot"\nnamespace = "/base"\n'
        'parameters = { speed = 2.0 }\nremap = { "/a" = "/b" }\n'
    )
    monkeypatch.syspath_prepend(str(tmp_path))
    [(node, _)] = build_nodes(load_config(path))
    assert node.get_fully_qualified_name() == "/base/robot"
    assert node.get_parameter("speed").value == 2.0
    assert node.resolve_topic_name("/a") == "/b"
