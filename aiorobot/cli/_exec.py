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
    from .._core._transport import transport_names

    parser.add_argument(
        "--transport", choices=transport_names(), default="local",
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
    return run_script(
        [args.script, *args.args], prog="aiorobot exec", transport=args.transport, nodes=args.node,
        interfaces=args.interfaces,
    )


def run_script(
    argv: Sequence[str], *, prog: str, transport: str = "local", nodes: Sequence[str] = (),
    interfaces: Sequence[str] = (),
) -> int:
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
    from .._core._ros_args import RosArgsError, parse_ros_args
    from ..compat import resolve_entry_point, run_entry_point, run_path
    from ..compat._context import settings

    for spec in nodes:
        module_name, sep, attr = spec.partition(":")
        if not sep or not module_name or not attr:
            print(f"{prog}: error: --node: expected MODULE:CLASS, found {spec!r}", file=sys.stderr)
            return 2
    settings.transport = transport
    settings.nodes = list(nodes)
    error = _register_interfaces(interfaces)
    if error:
        print(f"{prog}: error: {error}", file=sys.stderr)
        return 2

    try:
        parse_ros_args(rest)
    except RosArgsError as err:
        print(f"{prog}: error: {err}", file=sys.stderr)
        return 2
    from ..compat import NotProvidedError
    from ..compat._finder import missing_package
    from ..compat._missing import MissingInterfaceError

    try:
        if entry_point:
            try:
                resolve_entry_point(script)
            except ValueError as err:
                print(f"{prog}: error: {err}", file=sys.stderr)
                return 2
            return run_entry_point(script, rest)
        run_path(script, rest)
    except (NotProvidedError, MissingInterfaceError) as err:
        # the program reached an rclpy name or an interface type aiorobot lacks: say where, in one line
        print(f"{prog}: {_user_frame(err.__traceback__)}{err}", file=sys.stderr)
        return 1
    except ModuleNotFoundError as err:
        # ``from my_msgs.msg import X`` of a package nobody registered: name the option, in one line
        package = _interface_package_import(err)
        if package is None:
            raise
        print(f"{prog}: {_user_frame(err.__traceback__)}{missing_package(package)}", file=sys.stderr)
        return 1
    return 0


def _register_interfaces(folders: Sequence[str]) -> str:
    """Register ``--interfaces`` folders and AIOROBOT_INTERFACES' together; the error line, '' if none."""
    from ..msgs import register_package
    from ..msgs._ros_packages import ENV_VAR

    given = [p for value in folders for p in value.split(os.pathsep) if p]
    from_env = [p for p in os.environ.get(ENV_VAR, "").split(os.pathsep) if p]
    if not given and not from_env:
        return ""
    source = " and ".join(s for s, paths in (("--interfaces", given), (ENV_VAR, from_env)) if paths)
    try:
        register_package(*given, *from_env)
    except (ValueError, LookupError) as err:
        return f"{source}: {err}"
    return ""


def _user_location(tb: Any) -> tuple[str, int] | None:
    """(file, line) of the innermost frame of the program's own code in ``tb`` (None if none)."""
    import aiorobot

    ours = os.path.dirname(os.path.abspath(aiorobot.__file__))
    where = None
    while tb is not None:
        filename = tb.tb_frame.f_code.co_filename
        if not filename.startswith("<") and not os.path.abspath(filename).startswith(ours) and "importlib" not in filename and not filename.endswith("runpy.py"):
            where = (filename, tb.tb_lineno)
        tb = tb.tb_next
    return where


def _user_frame(tb: Any) -> str:
    """``file:line: `` of the innermost frame of the program's own code in ``tb`` ('' if none)."""
    where = _user_location(tb)
    return f"{where[0]}:{where[1]}: " if where else ""


def _interface_package_import(err: ModuleNotFoundError) -> str | None:
    """The package ``P`` when ``err`` is a missing ``P`` imported as ``P.msg|srv|action`` at the program's line."""
    import linecache

    where = _user_location(err.__traceback__)
    if not err.name or where is None:
        return None
    package = err.name.partition(".")[0]
    line = linecache.getline(*where)
    if re.search(rf"(?<![\w.]){re.escape(package)}\.(?:msg|srv|action)\b", line) is None:
        return None
    return package
