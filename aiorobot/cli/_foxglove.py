"""``aiorobot foxglove [--port N]``: serve the running graph to the Foxglove app over WebSocket."""

from __future__ import annotations

import argparse
import os
import sys

from ._parser import positive_seconds, transport_name

__all__ = ["add_arguments", "main", "port_number"]


def port_number(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a port number 0..65535, found {text!r}") from None
    if not 0 <= value <= 65535:
        raise argparse.ArgumentTypeError(f"expected a port number 0..65535, found {text!r}")
    return value


def _folder(text: str) -> str:
    if not os.path.isdir(text):
        raise argparse.ArgumentTypeError(f"expected a folder of assets, found {text!r} (not a directory)")
    return text


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.description = (
        "Start a Foxglove WebSocket server (foxglove-sdk) showing every topic of the graph with its "
        "ros2msg schema, tf for the 3D panel, parameters and services of every node in every process; "
        "the app can publish (teleop, goal and initial poses) and fetch meshes. Open ws://HOST:PORT in Foxglove."
    )
    parser.add_argument("--port", type=port_number, default=8765, help="port to listen on (default 8765; 0 = any free port)")
    parser.add_argument("--host", default="127.0.0.1", help="address to listen on (default 127.0.0.1)")
    parser.add_argument("--max-large-hz", type=float, default=10.0, metavar="HZ", help="rate limit per image/cloud topic (default 10)")
    parser.add_argument("--asset-root", dest="asset_roots", action="append", type=_folder, default=[], metavar="DIR",
                        help="serve package:// and file:// assets from DIR (repeatable; besides $AMENT_PREFIX_PATH's share folders)")
    parser.add_argument("--use-sim-time", action="store_true", help="follow /clock and send it to the app as the time")
    parser.add_argument("--duration", type=positive_seconds, metavar="S", help="stop after S seconds (default: until Ctrl-C)")
    parser.add_argument("--transport", default="zenoh", type=transport_name, metavar="NAME", help="how to reach the graph (default zenoh)")
    parser.add_argument("--domain-id", type=int, default=None, metavar="N", help="ROS domain id (default: $ROS_DOMAIN_ID or 0)")


def main(args: argparse.Namespace) -> int:
    import aiorobot

    try:
        return int(aiorobot.run(_serve(args)))
    except (OSError, NotImplementedError, ValueError) as err:
        print(f"aiorobot foxglove: error: {err}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        return 130


async def _serve(args: argparse.Namespace) -> int:
    from aiorobot import Runtime
    from aiorobot.foxglove import FoxgloveBridge

    kw: dict[str, object] = {"transport": args.transport, "use_sim_time": args.use_sim_time}
    if args.domain_id is not None:
        kw["domain_id"] = args.domain_id
    async with Runtime(**kw) as rt:
        bridge = FoxgloveBridge(host=args.host, port=args.port, max_large_hz=args.max_large_hz, asset_roots=args.asset_roots)
        rt.add_node(bridge)
        print(f"Foxglove bridge on ws://{args.host}:{bridge.bound_port} (Ctrl-C to stop)", file=sys.stderr)
        await rt.spin(duration_sec=args.duration)
        stats = bridge.statistics()
    print(f"served {stats.channels} topic(s); {stats.sent} messages sent, {stats.throttled} throttled, {stats.dropped} dropped", file=sys.stderr)
    return 0
