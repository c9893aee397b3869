"""The Foxglove bridge, checked with a real WebSocket client (the `websockets` package).

foxglove-sdk 0.30 accepts only the ``foxglove.sdk.v1`` subprotocol name (see INTEROP.md); the
messages are those of the Foxglove WebSocket protocol v1 (JSON ops, binary messageData).
"""

from __future__ import annotations

import asyncio
import json
import struct
from typing import Any

import pytest

from aiorobot import Node, Runtime
from aiorobot.foxglove import FoxgloveBridge
from aiorobot.msgs.geometry_msgs import Twist, Vector3

websockets = pytest.importorskip("websockets")


async def _recv_json(ws: Any, op: str, timeout: float = 20.0) -> dict[str, Any]:
    async with asyncio.timeout(timeout):
        while True:
            frame = await ws.recv()
            if isinstance(frame, str):
                doc = json.loads(frame)
                if doc.get("op") == op:
                    return doc


async def test_a_websocket_client_subscribes_and_decodes_with_the_advertised_schema() -> None:
    from mcap_ros2._dynamic import generate_dynamic

    async with Runtime(handle_signals=False) as rt:
        bridge = FoxgloveBridge(port=0)
        rt.add_node(bridge)
        talker = Node("talker")
        pub = talker.create_publisher(Twist, "/cmd_vel", 10)
        rt.add_node(talker)
        url = f"ws://127.0.0.1:{bridge.bound_port}"
        async with websockets.connect(url, subprotocols=["foxglove.sdk.v1"]) as ws:
            info = await _recv_json(ws, "serverInfo")
            assert "parameters" in info["capabilities"]
            advertised = await _recv_json(ws, "advertise")
            channel = next(c for c in advertised["channels"] if c["topic"] == "/cmd_vel")
            assert channel["encoding"] == "cdr" and channel["schemaEncoding"] == "ros2msg"
            assert channel["schemaName"] == "geometry_msgs/msg/Twist"
            await ws.send(json.dumps({"op": "subscribe", "subscriptions": [{"id": 7, "channelId": channel["id"]}]}))
            decode = generate_dynamic(channel["schemaName"], channel["schema"])[channel["schemaName"]]
            async with asyncio.timeout(20):
                while True:  # publish until the subscription is in place and a message arrives
                    pub.publish(Twist(linear=Vector3(x=1.5), angular=Vector3(z=-0.25)))
                    try:
                        frame = await asyncio.wait_for(ws.recv(), 0.1)
                    except TimeoutError:
                        continue
                    if isinstance(frame, bytes) and frame[0] == 0x01:
                        break
            sub_id, log_time = struct.unpack_from("<IQ", frame, 1)
            assert sub_id == 7 and log_time > 0
            msg = decode(frame[13:])
            assert (msg.linear.x, msg.angular.z) == (1.5, -0.25)
        assert bridge.statistics().sent >= 1


async def test_parameters_of_every_node_are_listed_and_settable_from_the_app() -> None:
    async with Runtime(handle_signals=False) as rt:
        bridge = FoxgloveBridge(port=0)
        rt.add_node(bridge)
        node = Node("tuned")
        node.declare_parameter("gain", 0.5)
        rt.add_node(node)
        async with websockets.connect(f"ws://127.0.0.1:{bridge.bound_port}", subprotocols=["foxglove.sdk.v1"]) as ws:
            await _recv_json(ws, "serverInfo")
            await ws.send(json.dumps({"op": "getParameters", "parameterNames": ["/tuned.gain"], "id": "a"}))
            values = await _recv_json(ws, "parameterValues")
            assert values["parameters"] == [{"name": "/tuned.gain", "value": 0.5, "type": "float64"}] or values["parameters"][0]["value"] == 0.5
            await ws.send(json.dumps({"op": "setParameters", "parameters": [{"name": "/tuned.gain", "value": 0.75}], "id": "b"}))
            await _recv_json(ws, "parameterValues")
        assert node.get_parameter("gain").value == 0.75


async def test_garbage_from_a_client_does_not_crash_the_bridge() -> None:
    async with Runtime(handle_signals=False) as rt:
        bridge = FoxgloveBridge(port=0)
        rt.add_node(bridge)
        talker = Node("talker")
        pub = talker.create_publisher(Twist, "/cmd_vel", 10)
        rt.add_node(talker)
        async with websockets.connect(f"ws://127.0.0.1:{bridge.bound_port}", subprotocols=["foxglove.sdk.v1"]) as ws:
            await _recv_json(ws, "serverInfo")
            await ws.send("{not json")
            await ws.send(json.dumps({"op": "subscribe", "subscriptions": [{"id": 1, "channelId": 99999}]}))
            await ws.send(b"\xff\x00garbage")
        pub.publish(Twist())
        async with websockets.connect(f"ws://127.0.0.1:{bridge.bound_port}", subprotocols=["foxglove.sdk.v1"]) as ws:
            assert (await _recv_json(ws, "serverInfo"))["op"] == "serverInfo"


async def test_a_service_of_the_graph_is_called_from_the_app() -> None:
    from aiorobot.msgs import deserialize, serialize
    from aiorobot.msgs.example_interfaces import AddTwoInts

    async with Runtime(handle_signals=False) as rt:
        server = Node("adder")
        server.create_service(AddTwoInts, "/add_two_ints", lambda req: AddTwoInts.Response(sum=req.a + req.b))
        rt.add_node(server)
        bridge = FoxgloveBridge(port=0)
        rt.add_node(bridge)
        async with websockets.connect(f"ws://127.0.0.1:{bridge.bound_port}", subprotocols=["foxglove.sdk.v1"]) as ws:
            await _recv_json(ws, "serverInfo")
            services = (await _recv_json(ws, "advertiseServices"))["services"]
            service = next(s for s in services if s["name"] == "/add_two_ints")
            payload = serialize(AddTwoInts.Request(a=2, b=40))
            await ws.send(struct.pack("<BIII", 0x02, service["id"], 11, 3) + b"cdr" + payload)
            async with asyncio.timeout(20):
                while True:
                    frame = await ws.recv()
                    if isinstance(frame, bytes) and frame[0] == 0x03:
                        break
            service_id, call_id, enc_len = struct.unpack_from("<III", frame, 1)
            assert (service_id, call_id) == (service["id"], 11)
            response = deserialize(frame[13 + enc_len:], AddTwoInts.Response)
        assert response.sum == 42
