"""The runtime's statistics: per-callback figures, and ``~/get_statistics`` reading them as JSON."""

from __future__ import annotations

import json

from aiorobot import Node, QoSProfile, Runtime
from aiorobot.msgs.std_msgs import String
from aiorobot.msgs.std_srvs import Trigger

from tests.transport._helpers import wait_until


async def test_get_statistics_reports_callbacks_queues_drops_and_publishers() -> None:
    async with Runtime(handle_signals=False) as rt:
        talker = rt.add_node(Node("talker"))
        pub = talker.create_publisher(String, "/chatter", 10)
        listener = rt.add_node(Node("listener"))
        heard: list[str] = []
        listener.create_subscription(String, "/chatter", lambda m: heard.append(m.data), QoSProfile(depth=2))
        for i in range(5):  # the dispatcher has not run yet: depth 2 keeps the last two, drops three
            pub.publish(String(data=str(i)))
        await wait_until(lambda: len(heard) == 2)
        reader = rt.add_node(Node("reader", start_parameter_services=False))
        assert "/reader/get_statistics" not in [s.srv_name for s in reader.services]
        client = reader.create_client(Trigger, "/listener/get_statistics")
        response = await client.call(Trigger.Request(), timeout_sec=5)
    assert response.success
    doc = json.loads(response.message)
    assert doc["schema"] == 1 and doc["process"]["nodes"] == 3 and doc["process"]["cpu_sec"] > 0
    node = doc["node"]
    assert node["name"] == "/listener" and node["executor"] == "main"
    (sub,) = [e for e in node["entities"] if e["kind"] == "subscription"]
    assert (sub["name"], sub["received"], sub["dropped"], sub["callbacks"], sub["depth"]) == ("/chatter", 5, 3, 2, 2)
    assert 0 < sub["time_p50_ms"] <= sub["time_max_ms"]
    assert {p["topic"] for p in node["publishers"]} == {"/parameter_events", "/rosout"}


async def test_callback_statistics_count_timer_calls() -> None:
    async with Runtime(handle_signals=False) as rt:
        node = rt.add_node(Node("ticker"))
        calls = []
        timer = node.create_timer(0.001, lambda: calls.append(1))
        await wait_until(lambda: len(calls) >= 5)
        stats = node._callback_stats[timer].statistics()
    assert stats.calls == len(calls)
    assert 0 < stats.time_p50_sec <= stats.time_p99_sec <= stats.time_max_sec
