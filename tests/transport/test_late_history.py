"""A transient-local subscription that joins while its publisher keeps publishing gets the history
the publisher keeps, once, even when it is made the moment its session opens (zenoh-ext's own
history query may go out before the session knows a route, and a live message delivered before a
later query's replies made zenoh-ext drop every older message: 1 late joiner in 6-8 lost the
history in a probe); a depth-1 latched topic never goes back to an older message."""

from __future__ import annotations

import contextlib
from collections.abc import Callable

from aiorobot import DurabilityPolicy, Node, QoSProfile, Runtime
from aiorobot.msgs.std_msgs import String
from aiorobot.transport import ZenohTransport

from ._helpers import Child, spawn, wait_until

# TOPIC, DEPTH: "history 0..4" before anyone listens, then "live N" every 5 ms
TALKER = """
from aiorobot.msgs.std_msgs import String
async def main(rt):
    qos = QoSProfile(depth=DEPTH, durability=DurabilityPolicy.TRANSIENT_LOCAL)
    pub = rt.add_node(Node("talker")).create_publisher(String, TOPIC, qos)
    for i in range(5):
        pub.publish(String(data=f"history {i}"))
    say("ready")
    n = 0
    while True:
        n += 1
        pub.publish(String(data=f"live {n}"))
        await asyncio.sleep(0.005)
"""
TRIALS = 12


async def _talker(port: int, depth: int) -> Child:
    child = await spawn(f"TOPIC = '/latched'\nDEPTH = {depth}\n" + TALKER, port)
    await child.expect("ready")
    return child


async def _join_late(port: int, depth: int, enough: Callable[[list[str]], bool], check: Callable[[int, list[str]], None]) -> None:
    """TRIALS late joiners of the talker's topic, each made as its session opens: ``check(trial,
    what it got)`` once it has ``enough``."""
    talker = await _talker(port, depth)
    try:
        for trial in range(TRIALS):
            got: list[str] = []
            async with Runtime(transport=ZenohTransport(connect=[f"tcp/127.0.0.1:{port}"]), handle_signals=False) as rt:
                qos = QoSProfile(depth=depth, durability=DurabilityPolicy.TRANSIENT_LOCAL)
                rt.add_node(Node("late")).create_subscription(String, "/latched", lambda m: got.append(m.data), qos)
                with contextlib.suppress(TimeoutError):  # (the check says what is missing)
                    await wait_until(lambda: enough(got), timeout_sec=10)
            check(trial, got)
    finally:
        await talker.stop()


async def test_a_late_joiner_made_as_its_session_opens_gets_the_history_once_while_the_publisher_publishes(
    router_port: int,
) -> None:
    def check(trial: int, got: list[str]) -> None:
        history = sorted(g for g in got if g.startswith("history"))  # (what the transport fetched may come last)
        assert history == [f"history {i}" for i in range(5)], f"trial {trial}: {got[:8]}"
        assert len(got) == len(set(got)), f"trial {trial}: delivered twice: {sorted(g for g in got if got.count(g) > 1)[:6]}"

    # (depth 10,000: the history stays in the talker's cache for 50 s)
    def enough(got: list[str]) -> bool:  # the history may come after live messages: its query waits for a route
        return sum(g.startswith("history") for g in got) >= 5 and sum(g.startswith("live") for g in got) >= 5

    await _join_late(router_port, 10_000, enough, check)


async def test_a_depth_1_latched_topic_never_goes_back_to_an_older_message(router_port: int) -> None:
    def check(trial: int, got: list[str]) -> None:
        numbers = [int(g.split()[1]) for g in got if g.startswith("live")]
        assert numbers == sorted(set(numbers)) and len(numbers) >= len(got) - 1, f"trial {trial}: {got}"  # newer each time

    await _join_late(router_port, 1, lambda got: len(got) >= 5, check)
