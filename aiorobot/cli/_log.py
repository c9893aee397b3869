"""``aiorobot log``: the graph's ``/rosout`` as a live console, every process's lines in one place.

Subscribes to ``/rosout`` (``rcl_interfaces/msg/Log``) over zenoh with rclpy's rosout
QoS, so the last lines every node kept (transient local, depth 1000, 10 s lifespan)
arrive first, then the live ones. Lines print in the node format
(``[INFO] [sec.nanosec] [robot.talker]: text``), filtered by ``--level`` (at least),
``--node`` (a node, with or without its leading ``/``; its child loggers too) and
``--regex`` (searched in the text).
"""

from __future__ import annotations

import argparse
import asyncio
import re
import sys
from typing import Any

from ._graph_session import add_graph_options, cli_node, join_graph

__all__ = ["add_arguments", "main"]

LEVEL_NAMES = {10: "DEBUG", 20: "INFO", 30: "WARN", 40: "ERROR", 50: "FATAL"}
_CHOICES = ("debug", "info", "warn", "error", "fatal")
_COLOURS = {10: "\033[2m", 30: "\033[33m", 40: "\033[31m", 50: "\033[1;31m"}


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--level", "-l", choices=_CHOICES, default="debug", type=str.lower,
                        help="show lines of at least this level (default: all)")
    parser.add_argument("--node", action="append", metavar="NAME",
                        help="only this node's lines (/robot/talker or robot.talker; repeat for more)")
    parser.add_argument("--regex", "-e", metavar="PATTERN", help="only lines whose text matches PATTERN (Python re)")
    parser.add_argument("--count", "-n", type=int, default=None, metavar="N", help="stop after N lines")
    parser.add_argument("--no-history", action="store_true",
                        help="skip the lines the nodes kept for late joiners; show only new ones")
    add_graph_options(parser)


def main(args: argparse.Namespace) -> int:
    from .. import run

    try:
        pattern = re.compile(args.regex) if args.regex is not None else None
    except re.error as err:
        print(f"aiorobot log: error: --regex: expected a Python regular expression, found {args.regex!r} ({err})",
              file=sys.stderr)
        return 2
    if args.count is not None and args.count < 1:
        print(f"aiorobot log: error: --count: expected a whole number >= 1, found {args.count}", file=sys.stderr)
        return 2
    try:
        return run(_follow(args, pattern))
    except KeyboardInterrupt:
        return 0


def logger_name(node: str) -> str:
    """rcl's logger name of a node given as ``/robot/talker``, ``robot/talker`` or ``robot.talker``."""
    return node.strip("/").replace("/", ".")


def accepts(msg: Any, level: int, nodes: list[str] | None, pattern: re.Pattern[str] | None) -> bool:
    """Whether a Log line passes the filters."""
    if msg.level < level:
        return False
    if nodes and not any(msg.name == n or msg.name.startswith(n + ".") for n in nodes):
        return False
    return pattern is None or pattern.search(msg.msg) is not None


def format_line(msg: Any, colour: bool = False) -> str:
    level = LEVEL_NAMES.get(msg.level, str(msg.level))
    text = f"[{level}] [{msg.stamp.sec}.{msg.stamp.nanosec:09d}] [{msg.name}]: {msg.msg}"
    if colour and msg.level in _COLOURS:
        return f"{_COLOURS[msg.level]}{text}\033[0m"
    return text


async def _follow(args: argparse.Namespace, pattern: re.Pattern[str] | None) -> int:
    from .._core._logging import ROSOUT_QOS
    from ..msgs.rcl_interfaces import Log

    level = {"debug": 10, "info": 20, "warn": 30, "error": 40, "fatal": 50}[args.level]
    nodes = [logger_name(n) for n in args.node] if args.node else None
    colour = sys.stdout.isatty()
    lines: asyncio.Queue[Any] = asyncio.Queue()
    async with join_graph(args) as rt:
        topic = rt.graph.topic("/rosout")
        own = {n.get_fully_qualified_name() for n in rt.nodes}
        if topic is None or not [p for p in topic.publishers if p.node not in own]:
            print("aiorobot log: no node of the graph publishes /rosout yet; waiting for lines (Ctrl-C stops)",
                  file=sys.stderr, flush=True)
        node = cli_node(rt, "aiorobot_log")
        qos = ROSOUT_QOS
        if args.no_history:
            from .. import DurabilityPolicy, QoSProfile

            qos = QoSProfile(reliability=qos.reliability, durability=DurabilityPolicy.VOLATILE, depth=qos.depth)
        node.create_subscription(Log, "/rosout", lines.put_nowait, qos)
        shown = 0
        while True:
            msg = await lines.get()
            if msg.name == node.get_logger().rosout_name or not accepts(msg, level, nodes, pattern):
                continue
            sys.stdout.write(format_line(msg, colour) + "\n")
            sys.stdout.flush()
            shown += 1
            if args.count is not None and shown >= args.count:
                return 0
