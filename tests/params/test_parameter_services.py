"""Every node's parameter services and /parameter_events, called through a runtime like any service."""

from __future__ import annotations

import asyncio

from aiorobot import Node, Parameter, ParameterDescriptor, Runtime, SetParametersResult
from aiorobot.msgs import rcl_interfaces as ri
from aiorobot.testing import settle


async def _call(node, srv, name, request):
    client = node.create_client(srv, name)
    await client.wait_for_service(timeout_sec=10)
    return await client.call(request, timeout_sec=10)


async def test_get_uninitialized_parameter():
    # rclpy test_parameter_service.py::test_get_uninitialized_parameter
    async with Runtime(handle_signals=False) as rt:
        target = rt.add_node(Node("test_node", namespace="/ns"))
        caller = rt.add_node(Node("caller"))
        target.declare_parameter("uninitialized_parameter", Parameter.Type.STRING)
        res = await _call(
            caller, ri.DescribeParameters, "/ns/test_node/describe_parameters",
            ri.DescribeParameters.Request(names=["uninitialized_parameter"]),
        )
        assert len(res.descriptors) == 1
        assert res.descriptors[0].type == ri.ParameterType.PARAMETER_STRING
        assert res.descriptors[0].name == "uninitialized_parameter"
        res = await _call(
            caller, ri.GetParameters, "/ns/test_node/get_parameters",
            ri.GetParameters.Request(names=["uninitialized_parameter"]),
        )
        assert res.values == []


async def test_parameter_services_get_set_list_types():
    # rclpy test_node.py::test_node_has_parameter_services and parameter_service.py's answers
    async with Runtime(handle_signals=False) as rt:
        target = rt.add_node(Node("target"))
        caller = rt.add_node(Node("caller"))
        target.declare_parameter("gain", 0.5, range=(0.0, 1.0))
        target.declare_parameter("name", "x")
        names = {info.name for info in rt.graph.services}
        for service in ("describe_parameters", "get_parameters", "get_parameter_types", "list_parameters",
                        "set_parameters", "set_parameters_atomically"):
            assert f"/target/{service}" in names

        res = await _call(caller, ri.GetParameters, "/target/get_parameters", ri.GetParameters.Request(names=["gain", "name"]))
        assert [(v.type, v.double_value, v.string_value) for v in res.values] == [(3, 0.5, ""), (4, 0.0, "x")]
        res = await _call(caller, ri.GetParameters, "/target/get_parameters", ri.GetParameters.Request(names=["gain", "nope"]))
        assert res.values == []  # one unknown name empties the answer, as rclpy
        res = await _call(caller, ri.GetParameterTypes, "/target/get_parameter_types",
                          ri.GetParameterTypes.Request(names=["gain", "name"]))
        assert res.types.tolist() == [3, 4]
        res = await _call(caller, ri.ListParameters, "/target/list_parameters", ri.ListParameters.Request())
        assert sorted(res.result.names) == ["gain", "name", "use_sim_time"]

        req = ri.SetParameters.Request(parameters=[
            Parameter("gain", value=0.25).to_parameter_msg(),
            Parameter("gain", value=5.0).to_parameter_msg(),
            Parameter("missing", value=1).to_parameter_msg(),
        ])
        res = await _call(caller, ri.SetParameters, "/target/set_parameters", req)
        assert [r.successful for r in res.results] == [True, False, False]
        assert "outside the range" in res.results[1].reason and "not declared" in res.results[2].reason
        assert target.get_parameter("gain").value == 0.25

        req = ri.SetParametersAtomically.Request(parameters=[
            Parameter("gain", value=0.75).to_parameter_msg(),
            Parameter("name", value=3).to_parameter_msg(),
        ])
        res = await _call(caller, ri.SetParametersAtomically, "/target/set_parameters_atomically", req)
        assert not res.result.successful and target.get_parameter("gain").value == 0.25


async def test_async_on_set_callback_is_awaited_by_the_service():
    async with Runtime(handle_signals=False) as rt:
        target = rt.add_node(Node("target"))
        caller = rt.add_node(Node("caller"))
        target.declare_parameter("a", 1)

        async def vet(params):
            await asyncio.sleep(0)
            return SetParametersResult(params[0].value < 10, "too big")

        target.add_on_set_parameters_callback(vet)
        req = ri.SetParameters.Request(parameters=[Parameter("a", value=50).to_parameter_msg()])
        res = await _call(caller, ri.SetParameters, "/target/set_parameters", req)
        assert res.results[0].reason == "too big"


async def test_start_parameter_services_false_creates_none():
    async with Runtime(handle_signals=False) as rt:
        rt.add_node(Node("quiet", start_parameter_services=False))
        assert not [info for info in rt.graph.services if info.name.startswith("/quiet/")]


async def test_parameter_events_on_declare_set_undeclare():
    # rclpy node.py _set_parameters_atomically_common: ParameterEvent new / changed / deleted
    async with Runtime(handle_signals=False) as rt:
        listener = rt.add_node(Node("listener"))
        events: list = []
        listener.create_subscription(ri.ParameterEvent, "/parameter_events", events.append, 100)
        target = rt.add_node(Node("target", namespace="/robot"))
        await settle(rt)
        target.declare_parameter("speed", 1.0, ParameterDescriptor(description="m/s"))
        target.set_parameters([Parameter("speed", value=2.0)])
        target.undeclare_parameter("speed")
        await settle(rt)
        mine = [e for e in events if e.node == "/robot/target"]
        assert [(len(e.new_parameters), len(e.changed_parameters), len(e.deleted_parameters)) for e in mine] == [
            (1, 0, 0), (0, 1, 0), (0, 0, 1),
        ]
        assert mine[0].new_parameters[0].name == "speed"
        assert mine[1].changed_parameters[0].value.double_value == 2.0
