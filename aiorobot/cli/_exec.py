"""``aiorobot exec script.py [args...]``: run an unmodified rclpy program on aiorobot."""

from __future__ import annotations

import argparse
import os
import re
import sys
from collections.abc import Sequence
from typing import Any

__all__ = ["add_arguments", "main", "run_script"]

#: ``package.module:function`` as in setup.py's ``console_scripts``
_ENTRY_POINT = re.compile(r"[A-Za-z_][\w.]*:[A-Za-z_][\w.]*")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--transport", choices=("local", "zenoh"), default="local",
        help="local: the program's nodes talk in-process (default); zenoh: with other processes "
        "(ZENOH_SESSION_CONFIG_URI / ZENOH_CONFIG_OVERRIDE apply, as in rmw_zenoh)",
    )
    parser.add_argument(
        "--node", action="append", default=[], metavar="MODULE:CLASS",
        help="also run this aiorobot node in the program's graph (repeatable): mixed graphs",
    )
    parser.add_argument(
        "script",
        help="a ROS 2 Python program (rclpy); it runs as __main__. Or MODULE:FUNCTION, a console_scripts "
        "entry point as in a package's setup.py (what `ros2 run` runs), with the module importable",
    )
    parser.add_argument("args", nargs=argparse.REMAINDER, help="its arguments (--ros-args ... included)")


def main(args: argparse.Namespace) -> int:
    return run_script([args.script, *args.args], prog="aiorobot exec", transport=args.transport, nodes=args.node)


def run_script(argv: Sequence[str], *, prog: str, transport: str = "local", nodes: Sequence[str] = ()) -> int:
    """Run ``argv[0]`` with the rclpy aliases; its exit status (SystemExit honoured)."""
    if not argv:
        print(f"{prog}: error: expected a script to run (e.g. {prog} talker.py)", file=sys.stderr)
        return 2
    script, *rest = argv
    entry_point = not os.path.exists(script) and _ENTRY_POINT.fullmatch(script) is not None
    if not entry_point and not os.path.isfile(script):
        print(
            f"{prog}: error: expected a Python file or MODULE:FUNCTION, found {script!r} (no such file)",
            file=sys.stderr,
        )
        return 2
    from .._ros_args import RosArgsError, parse_ros_args
    from ..compat import resolve_entry_point, run_entry_point, run_path
    from ..compat._context import settings

    for spec in nodes:
        module_name, sep, attr = spec.partition(":")
        if not sep or not module_name or not attr:
            print(f"{prog}: error: --node: expected MODULE:CLASS, found {spec!r}", file=sys.stderr)
            return 2
    settings.transport = transport
    settings.nodes = list(nodes)

    try:
        parse_ros_args(rest)
    except RosArgsError as err:
        print(f"{prog}: error: {err}", file=sys.stderr)
        return 2
    from ..compat import NotProvidedError

    try:
        if entry_point:
            try:
                resolve_entry_point(script)
            except ValueError as err:
                print(f"{prog}: error: {err}", file=sys.stderr)
                return 2
            return run_entry_point(script, rest)
        run_path(script, rest)
    except NotProvidedError as err:
        # the program reached an rclpy name aiorobot lacks: say where, in one line
        print(f"{prog}: {_user_frame(err.__traceback__)}{err}", file=sys.stderr)
        return 1
    return 0


def _user_frame(tb: Any) -> str:
    """``file:line: `` of the innermost frame of the program's own code in ``tb`` ('' if none)."""
    import aiorobot

    ours = os.path.dirname(os.path.abspath(aiorobot.__file__))
    where = ""
    while tb is not None:
        filename = tb.tb_frame.f_code.co_filename
        if not filename.startswith("<") and not os.path.abspath(filename).startswith(ours) and "importlib" not in filename and not filename.endswith("runpy.py"):
            where = f"{filename}:{tb.tb_lineno}: "
        tb = tb.tb_next
    return where
