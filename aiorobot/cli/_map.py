"""``aiorobot map save FILE``: save the graph's ``/map`` as map_server YAML + PGM (map_saver_cli)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ._parser import positive_seconds, transport_name

__all__ = ["add_arguments", "main"]


def add_arguments(parser: argparse.ArgumentParser) -> None:
    sub = parser.add_subparsers(dest="map_command", metavar="VERB", title="verbs")
    save = sub.add_parser("save", help="save the map being published as YAML + PGM (map_saver_cli)",
                          description="Wait for one map on TOPIC and write FILE.yaml and FILE.pgm.")
    save.add_argument("file", type=Path, metavar="FILE", help="output path without extension (FILE.yaml, FILE.pgm)")
    save.add_argument("-t", "--topic", default="/map", help="map topic (default /map)")
    save.add_argument("--timeout", type=positive_seconds, default=10.0, metavar="S", help="give up after S seconds (default 10)")
    save.add_argument("--transport", default="zenoh", type=transport_name, metavar="NAME", help="how to reach the graph (default zenoh)")


def main(args: argparse.Namespace) -> int:
    if args.map_command != "save":
        print("aiorobot map: error: expected a verb (save)", file=sys.stderr)
        return 2
    import aiorobot

    try:
        return int(aiorobot.run(_save(args)))
    except (NotImplementedError, OSError, TimeoutError) as err:
        print(f"aiorobot map save: error: {err or 'no map received'}", file=sys.stderr)
        return 1


async def _save(args: argparse.Namespace) -> int:
    from aiorobot import Node, Runtime
    from aiorobot.msgs.nav_msgs import OccupancyGrid
    from aiorobot.nav import OccupancyMap, save_map
    from aiorobot.nav._map_server import MAP_QOS
    from aiorobot.lowlevel import wait_for_message

    async with Runtime(transport=args.transport) as rt:
        node = rt.add_node(Node("map_saver"))
        try:
            msg = await wait_for_message(node, OccupancyGrid, args.topic, timeout_sec=args.timeout, qos=MAP_QOS)
        except TimeoutError:
            raise TimeoutError(f"no map on {args.topic} within {args.timeout:g} s") from None
    path = save_map(OccupancyMap.from_msg(msg), args.file)
    print(f"saved {msg.info.width}x{msg.info.height} map to {path} and {path.with_suffix('.pgm')}")
    return 0
