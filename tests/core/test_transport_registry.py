"""Transports are found by name: the core registers "local", importing aiorobot.transport registers "zenoh"."""

from __future__ import annotations

import asyncio
import subprocess
import sys

import pytest

from aiorobot import LocalTransport, Node, Runtime, Transport
from aiorobot._core import _transport
from aiorobot._core._transport import make_transport, register_transport, transport_names
from aiorobot.msgs.std_msgs import String


class RecordingTransport(Transport):
    """A transport that keeps what the runtime tells it (the seam's hooks, nothing faked)."""

    name = "recording"

    def __init__(self, *, domain_id: int = 0, label: str = "") -> None:
        super().__init__(domain_id=domain_id)
        self.label = label
        self.events: list[str] = []

    def node_added(self, node: Node) -> None:
        self.events.append(f"node {node.get_name()}")

    def endpoint_added(self, endpoint: object) -> None:
        self.events.append(f"endpoint {getattr(endpoint, 'topic_name', '?')}")


@pytest.fixture
def registry():
    saved = dict(_transport._REGISTRY)
    yield
    _transport._REGISTRY.clear()
    _transport._REGISTRY.update(saved)


def test_local_and_zenoh_are_registered_names() -> None:
    from aiorobot.transport import ZenohTransport

    assert {"local", "zenoh"} <= set(transport_names())
    assert type(make_transport("local", domain_id=3)) is LocalTransport
    zenoh = make_transport("zenoh", domain_id=5)
    assert type(zenoh) is ZenohTransport and zenoh.domain_id == 5


def test_the_core_imports_the_zenoh_package_only_when_zenoh_is_asked_for() -> None:
    code = (
        "import sys\n"
        "from aiorobot._core._transport import make_transport\n"
        "make_transport('local')\n"
        "assert not [m for m in sys.modules if m.startswith('aiorobot.transport')], 'local loaded zenoh'\n"
        "t = make_transport('zenoh')\n"
        "assert type(t).__module__ == 'aiorobot.transport._zenoh', type(t)\n"
    )
    subprocess.run([sys.executable, "-c", code], check=True, timeout=60)


def test_an_unknown_name_lists_the_registered_ones() -> None:
    with pytest.raises(ValueError, match=r"^transport: expected one of .*'local', .*'zenoh', found 'udp'$"):
        make_transport("udp")
    with pytest.raises(ValueError, match=r"^transport: expected one of .*, found 'udp'$"):
        Runtime(transport="udp")


def test_ros_domain_id_applies_to_zenoh_when_domain_id_is_left_at_0(monkeypatch) -> None:
    monkeypatch.setenv("ROS_DOMAIN_ID", "7")
    assert make_transport("zenoh").domain_id == 7
    assert make_transport("zenoh", domain_id=2).domain_id == 2
    assert make_transport("local").domain_id == 0
    monkeypatch.setenv("ROS_DOMAIN_ID", "seven")
    with pytest.raises(ValueError, match=r"^ROS_DOMAIN_ID: expected an int in 0\.\.232, found 'seven'$"):
        make_transport("zenoh")


def test_a_registered_transport_is_used_by_name_and_sees_the_graph(registry) -> None:
    register_transport("recording", RecordingTransport)
    register_transport("recording", RecordingTransport)  # the same factory again is harmless
    assert "recording" in transport_names()
    seen: list[RecordingTransport] = []

    async def main() -> None:
        async with Runtime(transport="recording", domain_id=4, handle_signals=False) as rt:
            transport = rt.transport
            assert isinstance(transport, RecordingTransport) and transport.domain_id == 4
            seen.append(transport)
            node = rt.add_node(Node("talker"))
            node.create_publisher(String, "/chatter", 10)

    asyncio.run(main())
    events = seen[0].events
    assert events[0] == "node talker" and "endpoint /chatter" in events, events


def test_registering_a_taken_name_or_a_bad_one_says_so(registry) -> None:
    with pytest.raises(ValueError, match=r"^transport 'local' is already registered to .*LocalTransport.*; pick another name$"):
        register_transport("local", RecordingTransport)
    with pytest.raises(ValueError, match=r"^transport name: expected an identifier such as 'zenoh', found 'tcp/1'$"):
        register_transport("tcp/1", RecordingTransport)
    with pytest.raises(TypeError, match=r"^transport 'x': expected a factory"):
        register_transport("x", "aiorobot.transport:ZenohTransport")  # type: ignore[arg-type]


def test_config_files_and_the_cli_accept_the_registrys_names_not_a_list_of_their_own(registry, tmp_path) -> None:
    from aiorobot.cli._exec import add_arguments
    from aiorobot.cli._parser import ArgumentParser
    from aiorobot.launch import load_config

    config = tmp_path / "graph.toml"
    config.write_text('[runtime]\ntransport = "recording"\n\n[[nodes]]\nuse = "aiorobot.examples:Talker"\n')
    from aiorobot._core._errors import ConfigError

    with pytest.raises(ConfigError, match=r'runtime\.transport: expected .*"local".*"zenoh", found "recording"'):
        load_config(config)
    parser = ArgumentParser(prog="aiorobot exec")
    add_arguments(parser)
    with pytest.raises(SystemExit):
        parser.parse_args(["--transport", "recording", "prog.py"])

    register_transport("recording", RecordingTransport)
    assert load_config(config).runtime.transport == "recording"
    assert parser.parse_args(["--transport", "recording", "prog.py"]).transport == "recording"


def test_an_unknown_transport_on_the_command_line_is_one_line_naming_the_choices() -> None:
    result = subprocess.run(
        [sys.executable, "-m", "aiorobot.cli", "exec", "--transport", "udp", "prog.py"],
        capture_output=True, text=True, timeout=60,
    )
    assert result.returncode == 2
    assert result.stderr.count("\n") == 1, result.stderr
    assert "--transport: expected one of" in result.stderr and "zenoh" in result.stderr and "'udp'" in result.stderr
