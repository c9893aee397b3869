"""time (sim time broadcast), assets (package:// and file:// under the roots, anything else
refused) and the replay of transient-local topics (robot_description) to late clients."""

from __future__ import annotations

import asyncio
import struct
from pathlib import Path

import pytest

from aiorobot import DurabilityPolicy, Node, QoSProfile, Runtime
from aiorobot.foxglove import FoxgloveBridge
from aiorobot.foxglove._assets import AssetRefused, AssetResolver
from aiorobot.msgs import deserialize
from aiorobot.msgs.std_msgs import String
from aiorobot.testing import SimClock

pytest.importorskip("websockets")
from foxglove_wsclient import ASSET_RESPONSE, MESSAGE_DATA, TIME, FoxgloveClient  # noqa: E402


async def test_sim_time_is_broadcast_and_repeated_while_the_clock_stands(sim_runtime: Runtime) -> None:
    sim = SimClock(sim_runtime)
    await sim.start()
    bridge = sim_runtime.add_node(FoxgloveBridge(port=0))
    async with FoxgloveClient(bridge.bound_port) as client:
        assert "time" in (await client.wait_op("serverInfo"))["capabilities"]
        await sim.set(5.0)

        def at_five() -> list[bytes]:
            return [f for f in client.frames(TIME) if struct.unpack_from("<Q", f, 1)[0] == 5_000_000_000]

        await client.until(lambda: len(at_five()) >= 3)  # sent again while /clock stands still
        await sim.set(7.25)
        await client.until(lambda: any(struct.unpack_from("<Q", f, 1)[0] == 7_250_000_000 for f in client.frames(TIME)))


async def test_no_time_capability_on_wall_time() -> None:
    async with Runtime(handle_signals=False) as rt:
        bridge = rt.add_node(FoxgloveBridge(port=0))
        async with FoxgloveClient(bridge.bound_port) as client:
            assert "time" not in (await client.wait_op("serverInfo"))["capabilities"]


def _robot(tmp: Path) -> Path:
    mesh = tmp / "assets" / "my_robot" / "meshes" / "base.stl"
    mesh.parent.mkdir(parents=True)
    mesh.write_bytes(b"solid base\nendsolid base\n")
    (tmp / "secret.txt").write_text("not for the app")
    return tmp / "assets"


def test_asset_resolver_serves_only_under_its_roots_and_share_folders(tmp_path: Path) -> None:
    root = _robot(tmp_path)
    prefix = tmp_path / "install"
    (prefix / "share" / "other_pkg" / "urdf").mkdir(parents=True)
    (prefix / "share" / "other_pkg" / "urdf" / "r.urdf").write_text("<robot/>")
    assets = AssetResolver([root], ament_prefix_path=str(prefix))
    assert assets("package://my_robot/meshes/base.stl").startswith(b"solid base")
    assert assets("package://other_pkg/urdf/r.urdf") == b"<robot/>"
    assert assets(f"file://{root}/my_robot/meshes/base.stl").startswith(b"solid base")
    refusals = {
        f"file://{tmp_path}/secret.txt": "file:// is served only under the asset roots",
        "package://my_robot/../../secret.txt": "not found",
        "http://example.com/base.stl": "expected a package:// or file:// URI",
        "meshes/base.stl": "expected a package:// or file:// URI",
        "package://my_robot/meshes/missing.stl": "not found: looked for meshes/missing.stl in",
    }
    for uri, reason in refusals.items():
        with pytest.raises(AssetRefused, match=reason):
            assets(uri)
    with pytest.raises(ValueError, match="asset_roots: expected a folder"):
        AssetResolver([tmp_path / "nope"])


async def test_assets_are_fetched_over_the_protocol_and_refusals_say_why(tmp_path: Path) -> None:
    root = _robot(tmp_path)
    async with Runtime(handle_signals=False) as rt:
        bridge = rt.add_node(FoxgloveBridge(port=0, asset_roots=[str(root)]))
        async with FoxgloveClient(bridge.bound_port) as client:
            assert "assets" in (await client.wait_op("serverInfo"))["capabilities"]
            await client.send({"op": "fetchAsset", "uri": "package://my_robot/meshes/base.stl", "requestId": 1})
            await client.send({"op": "fetchAsset", "uri": f"file://{tmp_path}/secret.txt", "requestId": 2})
            await client.until(lambda: len(client.frames(ASSET_RESPONSE)) >= 2)
    answers = {}
    for f in client.frames(ASSET_RESPONSE):
        request_id, status, n = struct.unpack_from("<IBI", f, 1)
        answers[request_id] = (status, f[10:10 + n].decode(), f[10 + n:])
    assert answers[1] == (0, "", b"solid base\nendsolid base\n")
    status, error, data = answers[2]
    assert status == 1 and "served only under the asset roots" in error and data == b""


async def test_robot_description_is_replayed_to_a_late_client_only() -> None:
    async with Runtime(handle_signals=False) as rt:
        rsp = rt.add_node(Node("robot_state_publisher"))
        pub = rsp.create_publisher(String, "/robot_description", QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL))
        bridge = rt.add_node(FoxgloveBridge(port=0))

        async def subscribe(client: FoxgloveClient) -> None:
            channel = await client.channel("/robot_description")
            await client.send({"op": "subscribe", "subscriptions": [{"id": 1, "channelId": channel["id"]}]})

        def texts(client: FoxgloveClient) -> list[str]:
            return [deserialize(f[13:], String).data for f in client.frames(MESSAGE_DATA)]

        async with FoxgloveClient(bridge.bound_port) as early:
            await subscribe(early)
            pub.publish(String(data="<robot name='v1'/>"))
            await early.until(lambda: texts(early))
            async with FoxgloveClient(bridge.bound_port) as late:
                await subscribe(late)
                await late.until(lambda: texts(late))
                assert texts(late) == ["<robot name='v1'/>"]
                pub.publish(String(data="<robot name='v2'/>"))
                await early.until(lambda: len(texts(early)) >= 2)
                await late.until(lambda: len(texts(late)) >= 2)
            assert texts(early) == ["<robot name='v1'/>", "<robot name='v2'/>"]  # no second copy of v1
            assert texts(late) == ["<robot name='v1'/>", "<robot name='v2'/>"]
async def test_a_subscription_the_bridge_hears_of_after_a_message_gets_that_message_once() -> None:
    # The server counts a subscription, then tells the bridge (its listener's on_subscribe). A
    # transient-local message published in between reached the client live and was then replayed to
    # it: twice. Here the notification is held back until the message has gone past.
    async with Runtime(handle_signals=False) as rt:
        rsp = rt.add_node(Node("robot_state_publisher"))
        pub = rsp.create_publisher(String, "/robot_description", QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL))
        probe = rsp.create_publisher(String, "/probe", 10)
        bridge = rt.add_node(FoxgloveBridge(port=0))
        held: list[tuple[int, str]] = []
        tell = bridge.replay_latched
        bridge.replay_latched = lambda client_id, topic: held.append((client_id, topic))  # type: ignore[method-assign]

        def texts(client: FoxgloveClient, channel_id: int) -> list[str]:
            return [deserialize(f[13:], String).data for f in client.frames(MESSAGE_DATA)
                    if struct.unpack_from("<I", f, 1)[0] == channel_id]

        async with FoxgloveClient(bridge.bound_port) as client:
            description, probe_channel = await client.channel("/robot_description"), await client.channel("/probe")
            await client.send({"op": "subscribe", "subscriptions": [
                {"id": description["id"], "channelId": description["id"]}, {"id": probe_channel["id"], "channelId": probe_channel["id"]}]})
            async with asyncio.timeout(20):  # the server has both subscriptions (told from its thread)
                while len(held) < 2:
                    await asyncio.sleep(0.005)
            pub.publish(String(data="<robot name='v1'/>"))
            probe.publish(String(data="after v1"))  # sent by the same thread after v1: v1 has gone past
            await client.until(lambda: texts(client, probe_channel["id"]))
            for client_id, topic in held:
                tell(client_id, topic)
            await client.until(lambda: texts(client, description["id"]))
            pub.publish(String(data="<robot name='v2'/>"))
            await client.until(lambda: len(texts(client, description["id"])) >= 2)
            assert texts(client, description["id"]) == ["<robot name='v1'/>", "<robot name='v2'/>"]


