"""The ``aiorobot`` command line.

Subcommands are registered by module path and imported only when invoked, so
``aiorobot --help`` stays fast (no numpy, numba or rosbags). A command module provides
``add_arguments(parser)`` and ``main(args) -> int``.
"""

from __future__ import annotations

import importlib
import os
import sys
from collections.abc import Sequence

from ._parser import ArgumentParser

__all__ = ["COMMANDS", "main"]

#: name -> (module implementing it, one-line help)
COMMANDS: dict[str, tuple[str, str]] = {
    "run": ("aiorobot.cli._run", "run a graph of nodes from a TOML config; with no file, the demo (the simulated robot's warehouse mission)"),
    "bench": ("aiorobot.bench._cli", "executor and transport latency benchmark"),
    "bag": ("aiorobot.cli._bag", "record, play, inspect and repair rosbag2 (MCAP) bags"),
    "foxglove": ("aiorobot.cli._foxglove", "serve the graph live to the Foxglove app (WebSocket)"),
    "plot": ("aiorobot.cli._plot", "plot message fields over time from a bag or the live graph"),
    "map": ("aiorobot.cli._map", "save the published map as map_server YAML + PGM"),
    "demo": ("aiorobot.cli._demo", "the simulated robot navigating a waypoint mission, with a summary"),
    "sim": ("aiorobot.cli._sim", "run the simulated robot in a world (lidar, IMU, odometry, camera)"),
    "router": ("aiorobot.cli._router", "a zenoh router joining graphs across processes and machines (rmw_zenohd)"),
    "topic": ("aiorobot.cli._topic", "topics of the running graph: list, info, echo, pub, hz, bw"),
    "node": ("aiorobot.cli._node_cmd", "nodes of the running graph: list, info"),
    "service": ("aiorobot.cli._service", "services of the running graph: list, call"),
    "action": ("aiorobot.cli._action", "actions of the running graph: list, info, send_goal"),
    "graph": ("aiorobot.cli._graph_cmd", "the running graph's nodes and topics, as text, Graphviz or an HTML page"),
    "param": ("aiorobot.cli._param_cmd", "parameters of the running graph's nodes: list, get, set, dump, load, describe"),
    "lifecycle": ("aiorobot.cli._lifecycle_cmd", "lifecycle nodes of the running graph: nodes, get, set, list"),
    "log": ("aiorobot.cli._log", "the graph's /rosout as a live console, every process's lines (level, node, regex filters)"),
    "top": ("aiorobot.cli._top", "every node of every process live: CPU, callbacks/s, callback time, queues, lateness, culprits"),
    "tf": ("aiorobot.cli._tf_cmd", "transforms of the running graph: echo (tf2_echo), tree (view_frames)"),
    "interface": ("aiorobot.cli._interface_cmd", "message, service and action types: list, packages, package, show"),
    "exec": ("aiorobot.cli._exec", "run an unmodified rclpy program (ROS 2 Python) on aiorobot"),
}


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``aiorobot`` console script; returns the exit status.

    Ctrl-C while a command is still importing or starting ends with one line and status 130,
    not a traceback through the import machinery. A reader that goes away (``aiorobot topic
    echo /scan | head``) ends the command quietly, as it ends ``cat``: status 141 (SIGPIPE).
    """
    try:
        return _main(argv)
    except KeyboardInterrupt:
        print("aiorobot: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        _silence_stdout()
        return 141
    except Exception as err:
        status = _one_line_error(err)
        if status is None:
            raise
        return status


def _one_line_error(err: Exception) -> int | None:
    """A configuration error (exit 2) or a refused zenoh session (exit 1) that reached the top
    from any command, printed as its one line; None for anything else (a bug: the traceback stays).
    The session error is looked up only if its module was imported, so raising it imported it."""
    from aiorobot._core._errors import ConfigError  # the core's exceptions: imports nothing else

    if isinstance(err, ConfigError):
        print(err, file=sys.stderr)
        return 2
    session = sys.modules.get("aiorobot.transport._session_config")
    if session is not None and isinstance(err, session.ZenohSessionError):
        print(f"aiorobot: error: {err}", file=sys.stderr)
        return 1
    return None


def _silence_stdout() -> None:
    """Point stdout at /dev/null so the interpreter's final flush of a closed pipe stays quiet."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.close(devnull)
    except (OSError, ValueError):
        pass


def _main(argv: Sequence[str] | None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    parser = ArgumentParser(
        prog="aiorobot",
        description="aiorobot: asyncio-native robotics, speaking ROS 2's types.",
    )
    parser.add_argument("--version", action="version", version=f"aiorobot {_version()}")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND", title="commands")

    chosen = _chosen_command(argv)
    module = None
    if chosen is not None:
        module_name = COMMANDS[chosen][0]
        try:
            module = importlib.import_module(module_name)
        except ModuleNotFoundError as err:
            if err.name is None or not module_name.startswith(err.name):
                raise
            print(
                f"aiorobot: error: the {chosen!r} command is not available in this installation "
                f"({module_name} is missing)",
                file=sys.stderr,
            )
            return 2
    for name, (_, help_text) in COMMANDS.items():
        sub = subparsers.add_parser(name, help=help_text, description=help_text)
        if name == chosen and module is not None:
            module.add_arguments(sub)

    try:
        args = parser.parse_args(argv)
        if module is None:
            parser.error(f"expected a command ({', '.join(COMMANDS)}), found none")
    except SystemExit as exit_:  # --help, --version and bad arguments
        return exit_.code if isinstance(exit_.code, int) else 1
    return int(module.main(args))


def _chosen_command(argv: list[str]) -> str | None:
    """The subcommand named in ``argv``: the first argument that is not an option."""
    for arg in argv:
        if arg == "--":
            return None
        if not arg.startswith("-"):
            return arg if arg in COMMANDS else None
    return None


def _version() -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("aiorobot")
    except PackageNotFoundError:  # pragma: no cover - running from a bare checkout
        return "unknown"
