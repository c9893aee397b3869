"""``aiorobot topic list|info|echo|pub|hz|bw``: ros2 topic against a running graph (zenoh)."""

from __future__ import annotations

import argparse
import asyncio
import sys
import time
from typing import Any

from ._graph_session import UserError, add_graph_options, fill_message, join_graph, message_to_yaml, run_verb

__all__ = ["add_arguments", "main"]


def add_arguments(parser: argparse.ArgumentParser) -> None:
    verbs = parser.add_subparsers(dest="verb", metavar="VERB", required=True)
    p = verbs.add_parser("list", help="topics in the graph")
    p.add_argument("-t", "--show-types", action="store_true")
    p = verbs.add_parser("info", help="a topic's type, publishers and subscriptions")
    p.add_argument("name")
    p.add_argument("-v", "--verbose", action="store_true")
    for verb in ("echo", "hz", "bw"):
        p = verbs.add_parser(verb, help={"echo": "print messages as YAML", "hz": "message rate", "bw": "bandwidth"}[verb])
        p.add_argument("name")
        p.add_argument("type", nargs="?", default=None,
                       help="message type, e.g. std_msgs/msg/String (default: the type the graph shows; "
                            "a topic not published yet is waited for)")
        p.add_argument("--once", action="store_true", help="stop after one message (echo) or one report")
        p.add_argument("--count", "-n", type=int, default=None, help="stop after N messages")
    p = verbs.add_parser("pub", help="publish a message given as YAML")
    p.add_argument("name")
    p.add_argument("type", help="e.g. geometry_msgs/msg/Twist")
    p.add_argument("values", nargs="?", default="{}", help="YAML, e.g. '{linear: {x: 0.5}}'")
    p.add_argument("--once", "-1", action="store_true")
    p.add_argument("--times", "-t", type=int, default=None)
    p.add_argument("--rate", "-r", type=float, default=1.0)
    for sub in verbs.choices.values():
        add_graph_options(sub)


def main(args: argparse.Namespace) -> int:
    return run_verb("topic", args, _main, interrupted=0)


def _message_type(name: str) -> Any:
    from ..msgs import get

    try:
        return get(name)
    except Exception:
        raise UserError(f"type: expected a known message type such as geometry_msgs/msg/Twist, found {name!r}") from None


async def _main(args: argparse.Namespace) -> int:
    msg_type = _message_type(args.type) if getattr(args, "type", None) is not None else None  # before joining
    if args.verb == "pub":
        msg = fill_message(msg_type, args.values)  # before joining: a bad message starts nothing
    async with join_graph(args) as rt:
        graph = rt.graph
        if args.verb == "list":
            for t in graph.topics:
                print(f"{t.name} [{', '.join(t.types)}]" if args.show_types else t.name)
            return 0
        if args.verb == "info":
            return _info(graph, args)
        if args.verb == "pub":
            return await _pub(rt, args, msg_type, msg)
        return await _listen(rt, args, msg_type)


def _info(graph: Any, args: argparse.Namespace) -> int:
    topic = graph.topic(args.name)
    if topic is None:
        raise UserError(f"unknown topic {args.name!r}; 'aiorobot topic list' shows the topics")
    print(f"Type: {' | '.join(topic.types)}")
    print(f"Publisher count: {len(topic.publishers)}")
    print(f"Subscription count: {len(topic.subscriptions)}")
    if args.verbose:
        for e in (*topic.publishers, *topic.subscriptions):
            kind = "PUBLISHER" if e.kind == "publisher" else "SUBSCRIPTION"
            print(f"\nNode name: {e.node.rsplit('/', 1)[-1]}\nNode namespace: {e.node.rsplit('/', 1)[0] or '/'}")
            print(f"Topic type: {e.type}\nEndpoint type: {kind}")
            print(f"QoS profile:\n  Reliability: {e.qos.reliability.name}\n  History (Depth): {e.qos.history.name} ({e.qos.depth})")
            print(f"  Durability: {e.qos.durability.name}")
    return 0


async def _pub(rt: Any, args: argparse.Namespace, msg_type: Any, msg: Any) -> int:
    from .. import Node

    node = rt.add_node(Node(f"aiorobot_topic_pub_{int(time.time() * 1000) % 100000}"))
    pub = node.create_publisher(msg_type, args.name, 10)
    times = 1 if args.once else args.times
    deadline = time.monotonic() + 2.0
    while pub.get_subscription_count() == 0 and time.monotonic() < deadline:
        await asyncio.sleep(0.02)  # give subscribers a moment to match, as ros2 topic pub does
    matched = pub.get_subscription_count()
    if matched:
        print(f"matched {matched} subscriber{'s' if matched != 1 else ''} on {pub.topic_name}", flush=True)
    else:  # never publish into the void silently (no router, a typo in the topic, nobody listening yet)
        print(
            f"aiorobot topic pub: warning: no subscriber matched {pub.topic_name} within 2 s; "
            "publishing anyway ('aiorobot topic info' shows who is on it)",
            file=sys.stderr, flush=True,
        )
    n = 0
    while times is None or n < times:
        pub.publish(msg)
        n += 1
        print(f"publishing #{n}: {msg!r}")
        if times is not None and n >= times:
            break
        await asyncio.sleep(1.0 / args.rate)
    await asyncio.sleep(0.1)  # let the last put leave the process
    return 0


async def _wait_for_type(rt: Any, args: argparse.Namespace, msg_type: Any) -> Any:
    """The type to subscribe with; for a topic with no publisher yet, one warning, then (with no type
    given) wait until one appears, as ``ros2 topic echo`` / ``hz`` wait for the topic's type."""
    from ..msgs import get

    topic = rt.graph.topic(args.name)
    if topic is None or not topic.publishers:
        print(f"WARNING: topic [{args.name}] does not appear to be published yet; waiting for it (Ctrl-C stops)",
              file=sys.stderr, flush=True)
    elif msg_type is not None and msg_type.__msgtype__ not in topic.types:
        print(f"WARNING: topic [{args.name}] is published as {' | '.join(topic.types)}, not {msg_type.__msgtype__}: "
              "its messages will not arrive", file=sys.stderr, flush=True)
    while msg_type is None:
        topic = rt.graph.topic(args.name)
        if topic is not None and topic.publishers and topic.types:
            return get(topic.types[0])
        await asyncio.sleep(0.1)
    return msg_type


async def _listen(rt: Any, args: argparse.Namespace, msg_type: Any) -> int:
    from .. import Node, QoSProfile, ReliabilityPolicy
    from ..msgs import serialize

    msg_type = await _wait_for_type(rt, args, msg_type)
    # best effort subscribes to every publisher, reliable or not, as ros2 topic echo's default adapts
    qos = QoSProfile(reliability=ReliabilityPolicy.BEST_EFFORT, depth=10)
    node = rt.add_node(Node(f"aiorobot_topic_{args.verb}_{int(time.time() * 1000) % 100000}"))
    limit = 1 if (args.once and args.verb == "echo") else args.count
    n = 0
    stamps: list[float] = []
    sizes: list[int] = []
    last_report = time.monotonic()
    async for msg in node.subscribe(msg_type, args.name, qos):
        n += 1
        if args.verb == "echo":
            sys.stdout.write(message_to_yaml(msg) + "---\n")
            sys.stdout.flush()
        else:
            stamps.append(time.monotonic())
            if args.verb == "bw":
                sizes.append(len(serialize(msg)))
            if time.monotonic() - last_report >= 1.0 and len(stamps) >= 2:
                last_report = time.monotonic()
                _report(args.verb, stamps, sizes)
                if args.once:
                    return 0
        if limit is not None and n >= limit:
            if args.verb != "echo" and len(stamps) >= 2:
                _report(args.verb, stamps, sizes)
            return 0
    return 0


def _report(verb: str, stamps: list[float], sizes: list[int]) -> None:
    import numpy as np

    gaps = np.diff(stamps[-1000:])
    if verb == "hz":
        print(f"average rate: {1.0 / gaps.mean():.3f}\n\tmin: {gaps.min():.3f}s max: {gaps.max():.3f}s "
              f"std dev: {gaps.std():.5f}s window: {len(gaps) + 1}")
    else:
        window = sizes[-len(gaps) - 1:]
        rate = sum(window) / max(stamps[-1] - stamps[-len(window)], 1e-9)
        print(f"{rate:.0f} B/s from {len(window)} messages\n\tMessage size mean: {np.mean(window):.0f} B "
              f"min: {min(window)} B max: {max(window)} B")
