"""Service introspection: configure_introspection publishes rcl's events on <service>/_service_event."""

import pytest

from aiorobot import Node
from aiorobot._core._service_introspection import ServiceIntrospectionState
from aiorobot.msgs.example_interfaces import AddTwoInts
from aiorobot.testing import settle


def add(request):
    return AddTwoInts.Response(sum=request.a + request.b)


async def test_client_and_service_events_share_gid_and_sequence(runtime):
    server = runtime.add_node(Node("server"))
    service = server.create_service(AddTwoInts, "add", add)
    client_node = runtime.add_node(Node("client"))
    client = client_node.create_client(AddTwoInts, "add")
    events = []
    runtime.add_node(Node("echo")).create_subscription(AddTwoInts.Event, "/add/_service_event", events.append, 100)
    service.configure_introspection(server.get_clock(), 10, ServiceIntrospectionState.CONTENTS)
    client.configure_introspection(client_node.get_clock(), 10, ServiceIntrospectionState.METADATA)
    await settle(runtime)
    for a in (1, 2):
        await client.call(AddTwoInts.Request(a=a, b=10))
    await settle(runtime)
    assert [(e.info.event_type, e.info.sequence_number) for e in events] == [
        (0, 1), (1, 1), (2, 1), (3, 1), (0, 2), (1, 2), (2, 2), (3, 2),
    ]
    assert {bytes(e.info.client_gid) for e in events} == {client.gid}
    # the service shows contents, the client metadata only
    assert [(len(e.request), len(e.response)) for e in events[:4]] == [(0, 0), (1, 0), (0, 1), (0, 0)]
    assert events[2].response[0].sum == 11


async def test_off_stops_the_events(runtime):
    server = runtime.add_node(Node("server"))
    service = server.create_service(AddTwoInts, "add", add)
    client = runtime.add_node(Node("client")).create_client(AddTwoInts, "add")
    events = []
    runtime.add_node(Node("echo")).create_subscription(AddTwoInts.Event, "/add/_service_event", events.append, 100)
    service.configure_introspection(None, 10, ServiceIntrospectionState.METADATA)
    await settle(runtime)
    await client.call(AddTwoInts.Request(a=1, b=1))
    service.configure_introspection(None, 10, ServiceIntrospectionState.OFF)
    await client.call(AddTwoInts.Request(a=1, b=1))
    await settle(runtime)
    assert [e.info.event_type for e in events] == [1, 2]
    assert server.count_publishers("/add/_service_event") == 0


def test_a_state_that_is_not_one_says_which_are(runtime):
    service = runtime.add_node(Node("server")).create_service(AddTwoInts, "add", add)
    with pytest.raises(ValueError, match=r"^configure_introspection on /add: expected a ServiceIntrospectionState "
                                         r"\(OFF, METADATA, CONTENTS\), found 7$"):
        service.configure_introspection(None, 10, 7)
