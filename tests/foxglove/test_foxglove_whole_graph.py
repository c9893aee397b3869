"""The bridge serves the whole graph, not only its own process: a node in another process (over
zenoh) shows its parameters, takes new values, reports changes to a parametersSubscribe client,
and the services and topics it creates after the bridge started are offered, with the connection
graph saying who provides what."""

from __future__ import annotations

import asyncio
import re
import struct
import sys
from pathlib import Path

import pytest

from aiorobot.foxglove import FoxgloveBridge
from aiorobot.msgs import deserialize, serialize
from aiorobot.msgs.example_interfaces import AddTwoInts
from tests.transport._helpers import free_port, open_router, peer_env, peer_runtime, spawn

pytest.importorskip("websockets")
from foxglove_wsclient import SERVICE_RESPONSE, FoxgloveClient  # noqa: E402

CHILD = """
from aiorobot.msgs.example_interfaces import AddTwoInts
from aiorobot.msgs.std_msgs import String

async def main(rt):
    node = rt.add_node(Node("remote_tuner"))
    node.declare_parameter("gain", 0.5)
    node.declare_parameter("mode", "slow")
    say("READY")
    lines = await stdin_lines()
    while True:
        line = (await lines.readline()).decode().strip()
        if line == "SET":
            node.set_parameters([Parameter("gain", value=0.9)])
            say("SET")
        elif line == "SERVE":
            node.create_service(AddTwoInts, "/late_add", lambda req: AddTwoInts.Response(sum=req.a + req.b))
            pub = node.create_publisher(String, "/late_topic", 10)
            node.create_timer(0.05, lambda: pub.publish(String(data="late")))
            say("SERVED")
        elif not line:
            return
"""


def _values(doc: dict) -> dict:
    return {p["name"]: p.get("value") for p in doc["parameters"]}


async def test_parameters_services_and_topics_of_another_process() -> None:
    port = free_port()
    router = open_router(port)
    child = await spawn(CHILD, port)
    try:
        await child.expect("READY")
        async with peer_runtime(port) as rt:
            bridge = rt.add_node(FoxgloveBridge(port=0))
            async with FoxgloveClient(bridge.bound_port) as client:
                info = await client.wait_op("serverInfo")
                assert {"parameters", "parametersSubscribe", "services", "connectionGraph"} <= set(info["capabilities"])
                n = 0

                async def get_all() -> dict:
                    nonlocal n
                    n += 1
                    await client.send({"op": "getParameters", "parameterNames": [], "id": f"get{n}"})
                    return _values(await client.wait_op("parameterValues", lambda d, i=f"get{n}": d.get("id") == i))

                values = await get_all()
                for _ in range(400):  # until zenoh has told this process of the other node (polling, 20 s at most)
                    if "/remote_tuner.gain" in values:
                        break
                    await asyncio.sleep(0.05)
                    values = await get_all()
                assert values["/remote_tuner.gain"] == 0.5 and values["/remote_tuner.mode"] == "slow"
                assert "/foxglove_bridge.port" in values  # and the bridge's own, as before

                await client.send({"op": "setParameters", "parameters": [{"name": "/remote_tuner.gain", "value": 0.75}], "id": "set"})
                assert _values(await client.wait_op("parameterValues", lambda d: d.get("id") == "set")) == {"/remote_tuner.gain": 0.75}
                await client.send({"op": "getParameters", "parameterNames": ["/remote_tuner.gain"], "id": "check"})
                assert _values(await client.wait_op("parameterValues", lambda d: d.get("id") == "check")) == {"/remote_tuner.gain": 0.75}

                await client.send({"op": "subscribeParameterUpdates", "parameterNames": ["/remote_tuner.gain"]})
                await client.send({"op": "subscribeConnectionGraph"})
                await client.wait_op("connectionGraphUpdate")
                child.send("SET")
                await child.expect("SET")
                update = await client.wait_op("parameterValues", lambda d: "id" not in d and "/remote_tuner.gain" in _values(d))
                assert _values(update)["/remote_tuner.gain"] == 0.9

                child.send("SERVE")
                await child.expect("SERVED")
                service = await client.until(lambda: next((s for d in client.ops if d.get("op") == "advertiseServices"
                                                            for s in d["services"] if s["name"] == "/late_add"), None))
                channel = await client.channel("/late_topic")
                assert channel["schemaName"] == "std_msgs/msg/String"
                graph = await client.wait_op("connectionGraphUpdate", lambda d: any(
                    t["name"] == "/late_topic" and t["publisherIds"] == ["/remote_tuner"] for t in d["publishedTopics"]))
                assert {"name": "/late_add", "providerIds": ["/remote_tuner"]} in graph["advertisedServices"] or any(
                    d.get("op") == "connectionGraphUpdate" and {"name": "/late_add", "providerIds": ["/remote_tuner"]} in d["advertisedServices"]
                    for d in client.ops)

                await client._ws.send(struct.pack("<BIII", 0x02, service["id"], 5, 3) + b"cdr" + serialize(AddTwoInts.Request(a=20, b=22)))
                frame = await client.until(lambda: next((f for f in client.frames(SERVICE_RESPONSE)), None))
                _, call_id, enc_len = struct.unpack_from("<III", frame, 1)
                assert call_id == 5
                assert deserialize(frame[13 + enc_len:], AddTwoInts.Response).sum == 42
    finally:
        await child.stop()
        router.close()


async def test_the_aiorobot_foxglove_process_shows_another_process_parameters(tmp_path: Path) -> None:
    port = free_port()
    router = open_router(port)
    env = peer_env(tmp_path, port)
    child = await spawn(CHILD, port)
    bridge = await asyncio.create_subprocess_exec(sys.executable, "-m", "aiorobot.cli", "foxglove", "--port", "0", env=env,
                                                  stdout=asyncio.subprocess.DEVNULL, stderr=asyncio.subprocess.PIPE)
    try:
        await child.expect("READY")
        assert bridge.stderr is not None
        async with asyncio.timeout(30):
            found = None
            while found is None:
                line = (await bridge.stderr.readline()).decode()
                assert line, "aiorobot foxglove ended before serving"
                found = re.search(r"ws://127\.0\.0\.1:(\d+)", line)
        async with FoxgloveClient(int(found.group(1))) as client:
            await client.wait_op("serverInfo")
            for n in range(400):  # until zenoh has told the bridge's process of the other node (polling, 20 s at most)
                await client.send({"op": "getParameters", "parameterNames": ["/remote_tuner.gain"], "id": str(n)})
                values = _values(await client.wait_op("parameterValues", lambda d, i=str(n): d.get("id") == i))
                if values:
                    break
                await asyncio.sleep(0.05)
            assert values == {"/remote_tuner.gain": 0.5}
    finally:
        bridge.terminate()
        await bridge.wait()
        await child.stop()
        router.close()
