"""Secure zenoh graphs: mTLS and access control on loopback with throwaway certificates, and
what aiorobot says when a session is refused, misconfigured or alone (issues #34, #25 item 5)."""

from __future__ import annotations

import asyncio
import logging
import os
import sys
import threading
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

import aiorobot.transport._zenoh as zenoh_transport
from aiorobot import Node, Runtime
from aiorobot.msgs.std_msgs import String
from aiorobot.transport import ZenohConfigError, ZenohSessionError, ZenohTransport

from ._certs import Pki, make_pki, router_config, session_config
from ._helpers import free_port, open_router, peer_runtime, wait_until

REFUSALS = {
    # case -> (session_config options, what the one line says)
    "self-signed": (dict(cert="mallory"), "certificate rejected: the router refused this session's client certificate"),
    "no certificate": (dict(cert=None), "the router requires a client certificate (mTLS) and this session sent none"),
    "plain tcp": (dict(tls=False), "the listener there expects TLS: connect with tls/127.0.0.1:"),
}


@pytest.fixture(scope="module")
def pki(tmp_path_factory: pytest.TempPathFactory) -> Pki:
    return make_pki(tmp_path_factory.mktemp("pki"))


@pytest.fixture(scope="module")
def tls_router(pki: Pki, tmp_path_factory: pytest.TempPathFactory) -> Iterator[int]:
    """A router listening only on tls/127.0.0.1:<port>, mTLS required, /secret denied by its ACL
    (shared by the module's tests: each opens sessions of its own)."""
    import zenoh

    port = free_port()
    config = router_config(pki, port, tmp_path_factory.mktemp("router") / "router.json5")
    router = zenoh.open(zenoh.Config.from_file(str(config)))
    try:
        yield port
    finally:
        router.close()


def _runtime(config: Path, **kw: Any) -> Runtime:
    return Runtime(transport=ZenohTransport(config_file=str(config), **kw), handle_signals=False)


async def _cli(*argv: str, env: dict[str, str] | None = None, cwd: Path | None = None) -> tuple[int, str, str]:
    full_env = {k: v for k, v in os.environ.items() if not k.startswith(("ZENOH_", "AIOROBOT_ZENOH"))}
    full_env.update(env or {})
    proc = await asyncio.create_subprocess_exec(
        sys.executable, "-m", "aiorobot.cli", *argv, env=full_env, cwd=cwd,
        stdout=asyncio.subprocess.PIPE, stderr=asyncio.subprocess.PIPE,
    )
    out, err = await asyncio.wait_for(proc.communicate(), 30)
    return proc.returncode or 0, out.decode(), err.decode()


# -- the secure path works -------------------------------------------------------------------


async def test_mtls_clients_exchange_messages_and_the_routers_acl_holds(pki: Pki, tls_router: int, tmp_path: Path) -> None:
    alice = session_config(pki, tls_router, tmp_path / "alice.json5", cert="alice")
    bob = session_config(pki, tls_router, tmp_path / "bob.json5", cert="bob")
    async with _runtime(alice) as ra, _runtime(bob) as rb:
        talker, listener = ra.add_node(Node("talker")), rb.add_node(Node("listener"))
        got: dict[str, list[str]] = {"/chatter": [], "/secret": []}
        for topic, seen in got.items():
            listener.create_subscription(String, topic, lambda m, seen=seen: seen.append(m.data), 10)
        chatter = talker.create_publisher(String, "/chatter", 10)
        secret = talker.create_publisher(String, "/secret", 10)
        # the graph (liveliness tokens) passes; the ACL stops /secret's data at the router
        await wait_until(lambda: chatter.get_subscription_count() == 1 and secret.get_subscription_count() == 1)
        n = 0
        async with asyncio.timeout(20):
            while len(got["/chatter"]) < 10:
                n += 1
                secret.publish(String(data=f"secret {n}"))  # sent first, on the same link: it would arrive first
                chatter.publish(String(data=f"hello {n}"))
                await asyncio.sleep(0.01)
        assert got["/secret"] == []
        assert ra.transport.statistics().connect_failures == 0


# -- refused sessions: one line, in client and in peer mode ------------------------------------


@pytest.mark.parametrize("case", list(REFUSALS))
async def test_a_refused_client_raises_one_line_naming_the_endpoint_and_why(
    case: str, pki: Pki, tls_router: int, tmp_path: Path
) -> None:
    options, says = REFUSALS[case]
    config = session_config(pki, tls_router, tmp_path / "client.json5", mode="client", **options)
    with pytest.raises(ZenohSessionError) as caught:
        async with _runtime(config):
            pass
    line = str(caught.value)
    assert "\n" not in line
    assert line.startswith(f"zenoh session refused (client mode, {config}): ")
    assert f"127.0.0.1:{tls_router}: " in line and says in line


@pytest.mark.parametrize("case", list(REFUSALS))
async def test_a_refused_peer_warns_once_and_counts_it(
    case: str, pki: Pki, tls_router: int, tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    options, says = REFUSALS[case]
    config = session_config(pki, tls_router, tmp_path / "peer.json5", mode="peer", listen=[], **options)
    with caplog.at_level(logging.WARNING, logger="aiorobot.transport"):
        async with _runtime(config) as rt:
            assert rt.transport.statistics().connect_failures == 1
    warnings = [r.getMessage() for r in caplog.records if r.name == "aiorobot.transport"]
    assert len(warnings) == 1, warnings
    assert warnings[0].startswith(f"zenoh session (peer mode, {config}) could not connect to ")
    assert f"127.0.0.1:{tls_router}: " in warnings[0] and says in warnings[0]


async def test_the_cli_prints_a_refused_session_as_one_line_and_exits_1(pki: Pki, tls_router: int, tmp_path: Path) -> None:
    config = session_config(pki, tls_router, tmp_path / "mallory.json5", mode="client", cert="mallory")
    code, out, err = await _cli("topic", "list", env={"ZENOH_SESSION_CONFIG_URI": str(config)})
    assert code == 1
    assert err.splitlines() == [
        f"aiorobot: error: zenoh session refused (client mode, {config}): tls/127.0.0.1:{tls_router}: "
        + REFUSALS["self-signed"][1] + " (sslv3 alert certificate unknown: not signed by a CA it trusts?)"
    ]


# -- the plain-listener bypass ------------------------------------------------------------------


async def test_a_plain_listener_beside_tls_is_refused_at_start_up_because_peers_bypass_tls_and_the_acl(
    pki: Pki, tls_router: int, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # The former docs example: peer mode and no listen endpoints, so zenoh listens on tcp/[::]:0.
    documented = session_config(pki, tls_router, tmp_path / "doc.json5", mode="peer")
    with pytest.raises(ZenohConfigError) as caught:
        async with _runtime(documented):
            pass
    assert str(caught.value) == (
        f"{documented}: listen/endpoints: the config enables TLS (connect/endpoints has tls/127.0.0.1:{tls_router}) "
        "but listens on plain tcp/[::]:0 (zenoh's default for a peer that sets no listen endpoints): other processes "
        "could reach it past TLS and access control; listen on tls/ endpoints only, or use mode \"client\" with "
        "listen/endpoints [], or allow it with AIOROBOT_ZENOH_ALLOW_PLAIN=tcp/[::]:0"
    )
    plain = "tcp/127.0.0.1:0"
    alice = session_config(pki, tls_router, tmp_path / "alice.json5", mode="peer", cert="alice", listen=[plain])
    bob = session_config(pki, tls_router, tmp_path / "bob.json5", mode="peer", cert="bob", listen=[plain])
    with pytest.raises(ZenohConfigError, match=r"listen/endpoints: .* but listens on plain tcp/127\.0\.0\.1:0: "):
        async with _runtime(alice):
            pass
    # Allowed by name (the argument, or the variable), the bypass is real: the router denies
    # /secret, yet the two peers gossip their tcp listeners, link directly and exchange it.
    monkeypatch.setenv("AIOROBOT_ZENOH_ALLOW_PLAIN", plain)
    async with _runtime(alice, allow_plain=[plain]) as ra, _runtime(bob) as rb:
        got: list[str] = []
        rb.add_node(Node("listener")).create_subscription(String, "/secret", lambda m: got.append(m.data), 10)
        secret = ra.add_node(Node("talker")).create_publisher(String, "/secret", 10)
        await wait_until(lambda: secret.get_subscription_count() == 1)
        async with asyncio.timeout(20):
            while not got:
                secret.publish(String(data="leaked"))
                await asyncio.sleep(0.02)
        assert got[0] == "leaked"


# -- bad configs: one line naming the file, the key and the problem; nothing opened -----------------


async def test_bad_session_configs_are_one_line_before_zenoh_opens(pki: Pki, tmp_path: Path) -> None:
    bad = tmp_path / "bad.json5"
    bad.write_text('{ mode: "peer", connect: { endpoints: ["tls/127.0.0.1:1"] }\n')
    transport = ZenohTransport(config_file=str(bad))
    with pytest.raises(ZenohConfigError) as caught:
        async with Runtime(transport=transport, handle_signals=False):
            pass
    assert str(caught.value).startswith(f"{bad}: line 1, column ") and "not valid JSON5" in str(caught.value)
    assert "\n" not in str(caught.value) and transport._session is None

    missing = session_config(pki, 1, tmp_path / "missing.json5", mode="peer", listen=[])
    missing.write_text(missing.read_text().replace(pki.pem("alice"), str(tmp_path / "nowhere.pem")))
    transport = ZenohTransport(config_file=str(missing))
    with pytest.raises(ZenohConfigError) as caught:
        async with Runtime(transport=transport, handle_signals=False):
            pass
    assert str(caught.value) == (
        f"{missing}: transport/link/tls/connect_certificate: expected a PEM file, found no file at {tmp_path / 'nowhere.pem'}"
    )
    assert transport._session is None


async def test_the_cli_refuses_bad_configs_with_one_line_and_exit_2(pki: Pki, tmp_path: Path) -> None:
    bad = tmp_path / "bad.json5"
    bad.write_text("{ mode: 'peer', }}")
    code, out, err = await _cli("topic", "list", env={"ZENOH_SESSION_CONFIG_URI": str(bad)})
    assert (code, out) == (2, "")
    assert err.splitlines() == [f"{bad}: line 1, column 18: not valid JSON5 (expected EOI) (named by ZENOH_SESSION_CONFIG_URI)"]

    # a graph file's zenoh_config: checked with the graph, before any node is built
    zconf = session_config(pki, 1, tmp_path / "zenoh.json5", mode="peer", listen=[])
    zconf.write_text(zconf.read_text().replace(pki.key("alice"), str(tmp_path / "alice-gone.key")))
    graph = tmp_path / "graph.toml"
    graph.write_text('[runtime]\ntransport = "zenoh"\nzenoh_config = "zenoh.json5"\n'
                     '[[nodes]]\nname = "imu"\nuse = "aiorobot.examples.sensor:ImuPublisher"\n')
    code, out, err = await _cli("run", str(graph), "--duration", "5")
    assert (code, out) == (2, "")
    assert err.splitlines() == [
        f"{graph}: runtime.zenoh_config: {zconf}: transport/link/tls/connect_private_key: "
        f"expected a PEM file, found no file at {tmp_path / 'alice-gone.key'}"
    ]

    # the router: its certificate and its config file named
    rconf = router_config(pki, free_port(), tmp_path / "router.json5")
    rconf.write_text(rconf.read_text().replace(pki.pem("router"), "router-cert.pem"))
    code, out, err = await _cli("router", "--config", str(rconf), cwd=tmp_path)
    assert (code, out) == (2, "")
    assert err.splitlines() == [
        f"aiorobot router: error: {rconf}: transport/link/tls/listen_certificate: expected a PEM file, "
        f"found no file at {tmp_path / 'router-cert.pem'}"
    ]


async def test_the_router_prints_the_endpoints_it_listens_on(pki: Pki, tmp_path: Path) -> None:
    port = free_port()
    rconf = router_config(pki, port, tmp_path / "router.json5", acl=False)
    env = {k: v for k, v in os.environ.items() if not k.startswith("ZENOH_")}
    proc = await asyncio.create_subprocess_exec(
        sys.executable, "-m", "aiorobot.cli", "router", "--config", str(rconf), env=env,
        stdout=asyncio.subprocess.PIPE, stderr=asyncio.subprocess.PIPE,
    )
    try:
        assert proc.stdout is not None
        line = (await asyncio.wait_for(proc.stdout.readline(), 20)).decode()
        assert line.startswith("router ") and line.endswith(f" listening on tls/127.0.0.1:{port}\n"), line
        async with _runtime(session_config(pki, port, tmp_path / "alice.json5", cert="alice")) as rt:
            assert rt.transport.statistics().connect_failures == 0  # it does listen there
    finally:
        proc.terminate()
        await proc.wait()


# -- no silent isolation (issue #25 item 5) ------------------------------------------------------


@pytest.fixture
def default_router(monkeypatch: pytest.MonkeyPatch) -> str:
    """The default router endpoint moved to a free port, so no real router on 7447 interferes."""
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    monkeypatch.setattr(zenoh_transport, "DEFAULT_CONNECT", endpoint)
    monkeypatch.setattr(zenoh_transport, "_router_warned", threading.Event())
    for name in ("ZENOH_SESSION_CONFIG_URI", "ZENOH_CONFIG_OVERRIDE", "ZENOH_ROUTER_CHECK_ATTEMPTS"):
        monkeypatch.delenv(name, raising=False)
    return endpoint


async def test_a_default_session_without_a_router_warns_once(default_router: str, caplog: pytest.LogCaptureFixture) -> None:
    with caplog.at_level(logging.WARNING, logger="aiorobot.transport"):
        for _ in range(2):
            async with Runtime(transport=ZenohTransport(), handle_signals=False) as rt:
                assert rt.transport.statistics().connect_failures == 1
    assert [r.getMessage() for r in caplog.records if r.name == "aiorobot.transport"] == [
        f"no zenoh router at {default_router}; other processes will not be found: start `aiorobot router`"
    ]


async def test_no_warning_with_a_router_or_with_peer_endpoints(default_router: str, caplog: pytest.LogCaptureFixture) -> None:
    port = free_port()
    with caplog.at_level(logging.WARNING, logger="aiorobot.transport"):
        hub = ZenohTransport(listen=[f"tcp/127.0.0.1:{port}"])  # chose its endpoints: peer to peer
        async with Runtime(transport=hub, handle_signals=False):
            child = ZenohTransport(connect=[f"tcp/127.0.0.1:{port}", default_router])  # as aiorobot run's children
            async with Runtime(transport=child, handle_signals=False) as rt:
                assert rt.transport.statistics().connect_failures == 1  # counted, not warned: it has its hub
        router = open_router(int(default_router.rsplit(":", 1)[1]))
        try:
            async with Runtime(transport=ZenohTransport(), handle_signals=False) as rt:
                assert rt.transport.statistics().connect_failures == 0
        finally:
            router.close()
    assert [r.getMessage() for r in caplog.records if r.name == "aiorobot.transport"] == []


async def test_topic_pub_reports_how_many_subscribers_matched(router_port: int) -> None:
    async with peer_runtime(router_port) as rt:
        got: list[str] = []
        rt.add_node(Node("listener")).create_subscription(String, "/greeting", lambda m: got.append(m.data), 10)
        connect = ("--connect", f"tcp/127.0.0.1:{router_port}")
        code, out, err = await _cli("topic", "pub", "/greeting", "std_msgs/msg/String", "{data: hi}", "--once", *connect)
        assert code == 0, err
        assert out.splitlines()[0] == "matched 1 subscriber on /greeting"
        await wait_until(lambda: got == ["hi"])
        code, out, err = await _cli("topic", "pub", "/nobody", "std_msgs/msg/String", "{data: hi}", "--once", *connect)
        assert code == 0, err
        assert err.splitlines() == [
            "aiorobot topic pub: warning: no subscriber matched /nobody within 2 s; "
            "publishing anyway ('aiorobot topic info' shows who is on it)"
        ]


def test_the_plain_endpoint_check_reads_the_config_zenoh_will_use(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    from aiorobot.transport._zenoh import build_session_config

    for name in ("ZENOH_SESSION_CONFIG_URI", "ZENOH_CONFIG_OVERRIDE", "AIOROBOT_ZENOH_ALLOW_PLAIN"):
        monkeypatch.delenv(name, raising=False)
    acl_only = tmp_path / "acl.json5"  # access control alone secures a config too
    acl_only.write_text('{ mode: "peer", listen: { endpoints: { peer: ["tcp/127.0.0.1:0"] } }, '
                        'connect: { endpoints: [] }, access_control: { enabled: true } }')
    with pytest.raises(ZenohConfigError, match=r"enables access control \(access_control/enabled\) but listens on plain tcp/127\.0\.0\.1:0: "):
        build_session_config(config_file=str(acl_only))
    monkeypatch.setenv("AIOROBOT_ZENOH_ALLOW_PLAIN", "tcp/127.0.0.1:1, tcp/127.0.0.1:0")
    _, plan = build_session_config(config_file=str(acl_only))
    assert (plan.mode, plan.listen, plan.connect) == ("peer", ("tcp/127.0.0.1:0",), ())
    # the default session is not secured: no check; an override that secures it is checked
    _, plan = build_session_config()
    assert plan.secure is None
    monkeypatch.delenv("AIOROBOT_ZENOH_ALLOW_PLAIN")
    monkeypatch.setenv("ZENOH_CONFIG_OVERRIDE", "access_control/enabled=true")
    with pytest.raises(ZenohConfigError, match=r"^the default session config: listen/endpoints: .* plain tcp/127\.0\.0\.1:0: "):
        build_session_config()
    monkeypatch.setenv("ZENOH_CONFIG_OVERRIDE", "mode")
    with pytest.raises(ZenohConfigError, match=r"^ZENOH_CONFIG_OVERRIDE: expected key=value, found 'mode'$"):
        build_session_config()
    monkeypatch.delenv("ZENOH_CONFIG_OVERRIDE")
    monkeypatch.setenv("ZENOH_SESSION_CONFIG_URI", str(tmp_path / "gone.json5"))
    with pytest.raises(ZenohConfigError) as caught:
        build_session_config()
    assert str(caught.value) == (
        f"{tmp_path / 'gone.json5'}: expected a zenoh config file (JSON5) (named by ZENOH_SESSION_CONFIG_URI), "
        f"found no file at {tmp_path / 'gone.json5'}"
    )
