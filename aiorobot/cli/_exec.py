"""``aiorobot exec script.py [args...]``: run an unmodified rclpy program on aiorobot."""

from __future__ import annotations

import argparse
import os

from ._parser import transport_name

__all__ = ["add_arguments", "main"]


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--transport", type=transport_name, metavar="NAME", default="local",
        help="local: the program's nodes talk in-process (default); zenoh: with other processes "
        "(ZENOH_SESSION_CONFIG_URI / ZENOH_CONFIG_OVERRIDE apply, as in rmw_zenoh); dds: with ROS 2 "
        "nodes on DDS (ROS_DOMAIN_ID, ROS_AUTOMATIC_DISCOVERY_RANGE, CYCLONEDDS_URI apply, docs/dds.md)",
    )
    parser.add_argument(
        "--node", action="append", default=[], metavar="MODULE:CLASS",
        help="also run this aiorobot node in the program's graph (repeatable): mixed graphs",
    )
    parser.add_argument(
        "--interfaces", action="append", default=[], metavar="DIR",
        help="a ROS package folder (package.xml with msg/, srv/, action/) or a folder of them, whose "
        "interfaces the program imports (repeatable, or DIR1%sDIR2); AIOROBOT_INTERFACES lists more" % os.pathsep,
    )
    parser.add_argument(
        "script",
        help="a ROS 2 Python program (rclpy); it runs as __main__. Or MODULE:FUNCTION, a console_scripts "
        "entry point as in a package's setup.py (what `ros2 run` runs), with the module importable",
    )
    parser.add_argument("args", nargs=argparse.REMAINDER, help="its arguments (--ros-args ... included)")


def main(args: argparse.Namespace) -> int:
    from ..compat._run import run_script  # the rclpy aliases load only for exec

    return run_script(
        [args.script, *args.args], prog="aiorobot exec", transport=args.transport, nodes=args.node,
        interfaces=args.interfaces,
    )
