"""Node logging: node name, level, runtime clock time; per-node levels; throttling."""

import io
import logging

import pytest

from aiorobot import Node
from aiorobot._core._logging import NodeFormatter, parse_level, setup_logging


async def test_records_carry_node_name_and_sim_time(sim_runtime, sim_clock, caplog):
    node = sim_runtime.add_node(Node("talker", namespace="r1"))
    await sim_clock.advance(0.25)
    with caplog.at_level(logging.INFO):
        node.get_logger().info("hello")
    [record] = caplog.records
    assert record.node == "/r1/talker"
    assert record.ros_time_ns == 1_250_000_000
    assert NodeFormatter().format(record) == "[INFO] [1.250000000] [/r1/talker]: hello"


def test_per_node_level():
    quiet, loud = Node("quiet"), Node("loud")
    quiet.get_logger().set_level("error")
    loud.get_logger().set_level("debug")
    assert not quiet.get_logger().is_enabled_for("warning")
    assert loud.get_logger().is_enabled_for("debug")


def test_throttle_and_once(caplog):
    node = Node("n")
    with caplog.at_level(logging.INFO):
        for _ in range(5):
            node.get_logger().warning("throttled", throttle_duration_sec=3600)
        for _ in range(5):
            node.get_logger().info("once", once=True)
    assert [r.getMessage() for r in caplog.records] == ["throttled", "once"]


def test_bad_level_names_the_choices():
    with pytest.raises(ValueError, match=r"expected one of debug, error, fatal, info, warning, found 'loud'"):
        parse_level("loud")


def test_setup_logging_writes_the_ros_format():
    stream = io.StringIO()
    handler = setup_logging("info", stream)
    try:
        Node("n").get_logger().warning("careful")
    finally:
        logging.getLogger("aiorobot").removeHandler(handler)
        logging.getLogger("aiorobot").setLevel(logging.NOTSET)
    line = stream.getvalue().strip()
    assert line.startswith("[WARN] [") and line.endswith("] [/n]: careful")
