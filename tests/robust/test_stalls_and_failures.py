"""Loop-stall reports, callback failures counted and throttled, on_start failure policies."""

from __future__ import annotations

import asyncio
import logging
import time

import pytest

from aiorobot import Node, Runtime
from aiorobot.launch import ConfigError, load_config


class Blocker(Node):
    """Its first timer tick holds the loop (a blocking read, say), then it counts ticks."""

    def __init__(self, hold_sec: float) -> None:
        super().__init__("blocker")
        self.hold_sec = hold_sec
        self.ticks = 0
        self.create_timer(0.01, self.tick)

    def tick(self) -> None:
        self.ticks += 1
        if self.ticks == 1:
            time.sleep(self.hold_sec)  # the blocking call under test


async def wait_until(predicate, timeout_sec: float = 30.0) -> None:
    async with asyncio.timeout(timeout_sec):
        while not predicate():
            await asyncio.sleep(0.005)


@pytest.mark.parametrize("executor", ["main", "priority"])
async def test_a_stall_is_reported_once_with_node_entity_and_stack_and_counted(executor, caplog):
    caplog.set_level(logging.WARNING, logger="aiorobot.runtime")
    # the other loop's threshold is high: under load, starting the priority thread may stall main
    main, priority = (0.05, 10.0) if executor == "main" else (10.0, 0.05)
    async with Runtime(stall_threshold=main, priority_stall_threshold=priority) as rt:
        node = rt.add_node(Blocker(hold_sec=0.5), executor=executor)
        await wait_until(lambda: node.ticks >= 3)
        stats = rt.statistics()
    assert stats["stalls"] == {(executor, "/blocker", "timer 0.01s"): 1}
    reports = [r.getMessage() for r in caplog.records if "stalled" in r.getMessage()]
    assert len(reports) == 1
    assert f"{executor} loop stalled: timer 0.01s in /blocker" in reports[0]
    assert "in tick" in reports[0] and "time.sleep(self.hold_sec)" in reports[0]


async def test_a_stall_in_a_callback_run_on_delivery_names_its_subscription(caplog):
    # a transport runs an idle subscription's plain callback inside its delivery (deliver_eagerly),
    # outside the dispatcher task: the report still names the node and the subscription
    from aiorobot._core._pubsub import deliver_eagerly
    from aiorobot.msgs.std_msgs import Int32

    caplog.set_level(logging.WARNING, logger="aiorobot.runtime")
    async with Runtime(stall_threshold=0.05) as rt:
        node = rt.add_node(Node("reader"))
        pub = node.create_publisher(Int32, "/frames", 10)
        got: list[int] = []

        def read(msg: Int32) -> None:
            got.append(msg.data)
            time.sleep(0.5)  # the blocking call under test

        node.create_subscription(Int32, "/frames", read, 10)
        await rt.settle()
        asyncio.get_running_loop().call_soon(deliver_eagerly, pub.publish, Int32(data=1))
        await wait_until(lambda: rt.statistics()["stalls"] != {})
        stats = rt.statistics()
    assert got == [1]
    assert stats["stalls"] == {("main", "/reader", "subscription /frames"): 1}
    reports = [r.getMessage() for r in caplog.records if "stalled" in r.getMessage()]
    assert len(reports) == 1 and "main loop stalled: subscription /frames in /reader" in reports[0]


async def test_no_stall_is_reported_while_callbacks_are_short(caplog):
    async with Runtime(stall_threshold=0.5) as rt:
        node = rt.add_node(Blocker(hold_sec=0.0))
        await wait_until(lambda: node.ticks >= 20)
        assert rt.statistics()["stalls"] == {}


def test_thresholds_and_shutdown_timeout_are_checked():
    with pytest.raises(ValueError, match="shutdown_timeout: expected a number of seconds > 0, found -1"):
        Runtime(shutdown_timeout=-1)
    with pytest.raises(ValueError, match="priority_stall_threshold"):
        Runtime(priority_stall_threshold=0)


def test_config_keys(tmp_path):
    path = tmp_path / "g.toml"
    path.write_text(
        '[runtime]\nshutdown_timeout = 3\nstall_threshold = 0.2\npriority_stall_threshold = 0.01\n'
        '[[nodes]]\nuse = "m:C"\non_failure = "restart"\n'
    )
    cfg = load_config(path)
    assert (cfg.runtime.shutdown_timeout, cfg.runtime.stall_threshold, cfg.runtime.priority_stall_threshold) == (
        3.0,
        0.2,
        0.01,
    )
    assert cfg.nodes[0].on_failure == "restart"
    path.write_text('[runtime]\nshutdown_timeout = "soon"\n[[nodes]]\nuse = "m:C"\n')
    with pytest.raises(ConfigError, match="runtime.shutdown_timeout"):
        load_config(path)
    path.write_text('[[nodes]]\nuse = "m:C"\non_failure = "explode"\n')
    with pytest.raises(ConfigError, match="on_failure"):
        load_config(path)


class Faulty(Node):
    def __init__(self, *, fail_start: bool = False) -> None:
        super().__init__("faulty")
        self.fail_start = fail_start
        self.calls = 0
        self.create_timer(0.001, self.tick)

    async def on_start(self) -> None:
        if self.fail_start:
            raise RuntimeError("motor driver not found")

    def tick(self) -> None:
        self.calls += 1
        raise ValueError(f"bad reading {self.calls}")


async def test_first_failure_has_a_traceback_repeats_are_counted_not_logged(caplog):
    caplog.set_level(logging.ERROR)
    async with Runtime() as rt:
        node = rt.add_node(Faulty())
        await wait_until(lambda: node.calls >= 50)
        count = rt.statistics()["failures"][("/faulty", "callback of timer 0.001s")]
    assert count >= 50
    errors = [r for r in caplog.records if "raised" in r.getMessage()]
    assert errors[0].exc_info is not None and "bad reading 1" in str(errors[0].exc_info[1])
    assert len(errors) <= 2  # the first, and at most one throttled repeat line within 5 s


async def test_a_node_that_fails_to_start_stops_the_run_by_default():
    async with Runtime() as rt:
        rt.add_node(Faulty(fail_start=True))
        await asyncio.wait_for(rt.spin(), 30)  # returns: the failed start shut the runtime down
        assert rt.statistics()["failed_starts"] == ["/faulty"]


async def test_on_failure_continue_keeps_the_node_running():
    async with Runtime() as rt:
        node = Faulty(fail_start=True)
        node._on_failure = "continue"
        rt.add_node(node)
        await wait_until(lambda: rt.statistics()["failed_starts"] == ["/faulty"] and node.calls >= 5)
        assert not rt.is_shutdown


async def test_monitor_before_any_message_says_no_messages_yet():
    from aiorobot.examples.monitor import RateMonitor

    async with Runtime() as rt:
        monitor = rt.add_node(RateMonitor())
        assert "no messages yet" in monitor.status_line() and "nan" not in monitor.status_line()
        assert "no messages yet" in monitor.summary() and "nan" not in monitor.summary()
