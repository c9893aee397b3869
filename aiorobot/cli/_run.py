"""``aiorobot run [CONFIG.toml] [--duration SEC]``: run a graph of nodes from a config file.

Everything is loaded, imported, constructed and checked before the runtime starts, so a
bad file starts no node. SIGINT and SIGTERM shut the runtime down cleanly.

Nodes with ``process = "name"`` run in child processes that ``aiorobot run`` starts,
restarts and stops (see :mod:`aiorobot.cli._supervisor`); ``--process NAME`` runs only
the nodes of one process (what each child runs; ``main`` is the nodes without a process key).

Exit status: 0 after a clean run; 1 when a node failed to start or any callback raised
(listed per node and entity on stderr; ``--keep-going`` only keeps the other nodes
running), or a child process failed (even if restarted); 2 for a bad configuration;
124 when the shutdown did not finish within ``runtime.shutdown_timeout`` or a second
signal abandoned what was blocked (in any process); 130 when interrupted before the
runtime started.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ._parser import positive_seconds

if TYPE_CHECKING:
    from aiorobot import Node, Runtime
    from aiorobot.launch import GraphConfig

__all__ = ["add_arguments", "main"]

#: exit status for a bad configuration (as for bad command-line arguments)
EXIT_CONFIG_ERROR = 2
#: exit status when interrupted before the runtime could install its signal handlers
EXIT_INTERRUPTED = 130
#: exit status when a node failed to start or a callback raised (with or without --keep-going)
EXIT_FAILED = 1


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.description = (
        "Run a graph of nodes described by a TOML file: a [runtime] table and one [[nodes]] "
        "table per node (use = \"module:Class\"; the file's folder is importable). "
        "Without a file, run `aiorobot demo` (the simulated robot's waypoint mission; --duration "
        "then limits its sim time); the small example graph is aiorobot/examples/default.toml. "
        "Ctrl-C stops cleanly."
    )
    parser.add_argument(
        "config",
        nargs="?",
        type=Path,
        metavar="CONFIG.toml",
        help="graph configuration file (default: run the demo)",
    )
    parser.add_argument(
        "--duration",
        type=positive_seconds,
        metavar="SEC",
        help="stop after this many seconds (default: run until Ctrl-C or SIGTERM)",
    )
    parser.add_argument(  # `aiorobot run module:Class --ros-args ...`: see _run_node
        "--ros-args", dest="ros_args", nargs=argparse.REMAINDER, metavar="ARGS",
        help="with module:Class instead of a file: run that one node with ROS 2 arguments "
        "(-p name:=value, -r from:=to, --params-file FILE, --log-level LEVEL), as ros2 run",
    )
    parser.add_argument(
        "--status-period",
        type=positive_seconds,
        default=1.0,
        metavar="SEC",
        help="seconds between status lines (default: 1)",
    )
    parser.add_argument(
        "--keep-going",
        action="store_true",
        help="a node whose on_start raises does not stop the run (as on_failure = \"continue\" for "
        "nodes that leave on_failure at \"stop\"); the exit status is still 1 when a node failed "
        "to start or a callback raised",
    )
    parser.add_argument(
        "--process",
        metavar="NAME",
        help="run only the nodes with process = NAME (\"main\": those without a process key), "
        "without starting the other processes; each process of a multi-process file runs this way",
    )
    # set by the supervising `aiorobot run` on its children: its zenoh endpoint; stdin is its pipe
    parser.add_argument("--supervisor", metavar="ENDPOINT", help=argparse.SUPPRESS)


def main(args: argparse.Namespace) -> int:
    from aiorobot.launch import ConfigError, load_config

    from ._run_node import is_node_spec, run_node

    if args.config is not None and is_node_spec(str(args.config)):
        return run_node(args)
    if args.ros_args is not None:
        print("aiorobot run: error: --ros-args needs a module:Class, not a config file", file=sys.stderr)
        return EXIT_CONFIG_ERROR
    if args.config is None:  # no file: the demo (the small example graph is aiorobot/examples/default.toml)
        from ._demo import run_as_default

        return run_as_default(args.duration)
    config_path: Path = args.config
    if config_path.suffix == ".py":
        print(
            f"{config_path}: expected a TOML graph file (aiorobot run graph.toml), found a Python file; "
            f"to run one node class from it, use aiorobot run {config_path.stem}:ClassName",
            file=sys.stderr,
        )
        return EXIT_CONFIG_ERROR
    try:
        config = load_config(config_path)
    except ConfigError as err:
        print(err, file=sys.stderr)
        return EXIT_CONFIG_ERROR
    process = _process_of(args, config)
    if process is None:
        return EXIT_CONFIG_ERROR

    import aiorobot

    from ._logging import configure_logging

    configure_logging(config.runtime.log_level)
    try:
        from aiorobot.launch import build_nodes

        # Constructors run here, outside the event loop: a Ctrl-C interrupts one that blocks.
        nodes = build_nodes(config, process)  # raises ConfigError before anything starts
        return aiorobot.run(
            _serve(config, nodes, args.duration, args.status_period, args.keep_going, process=process,
                   supervisor=getattr(args, "supervisor", None), supervise=args.process is None)
        )
    except ConfigError as err:
        print(err, file=sys.stderr)
        return EXIT_CONFIG_ERROR
    except KeyboardInterrupt:  # before the signal handlers were in place
        print("interrupted before the graph started", file=sys.stderr)
        return EXIT_INTERRUPTED


def _process_of(args: argparse.Namespace, config: GraphConfig) -> str | None:
    """The process this invocation runs (``--process``, default ``main``); None after printing an error."""
    from aiorobot.launch import MAIN_PROCESS

    process = getattr(args, "process", None) or MAIN_PROCESS
    known = (MAIN_PROCESS, *config.child_processes)
    if process not in known:
        names = ", ".join(f'"{p}"' for p in known)
        print(f"{config.path}: --process: expected one of {names}, found \"{process}\"", file=sys.stderr)
        return None
    return process


async def _serve(
    config: GraphConfig,
    nodes: list[tuple[Node, str]],
    duration_sec: float | None,
    status_period_sec: float,
    keep_going: bool = False,
    *,
    process: str = "main",
    supervisor: str | None = None,
    supervise: bool = True,
) -> int:
    """Run ``process``'s nodes; the main process of a multi-process file also runs the others
    (``supervise``), a child started by one connects to its endpoint (``supervisor``)."""
    from ._supervisor import ProcessGroup

    group = ProcessGroup(config, process, supervisor=supervisor, supervise=supervise, status_period_sec=status_period_sec)
    try:
        status = await _serve_process(config, nodes, duration_sec, status_period_sec, keep_going, group, process)
    finally:
        await group.stop()
    return group.outcome(status)


async def _serve_process(
    config: GraphConfig,
    nodes: list[tuple[Node, str]],
    duration_sec: float | None,
    status_period_sec: float,
    keep_going: bool,
    group: Any,
    process: str,
) -> int:
    from aiorobot import Runtime
    from aiorobot.launch import ConfigError, node_configs, runtime_options
    from aiorobot.launch._open import zenoh_options
    from aiorobot.lowlevel import set_on_failure
    from ._status import StatusDisplay

    tables = node_configs(config, nodes, process)
    for (node, _), node_config in zip(nodes, tables):
        policy = node_config.on_failure if node_config is not None else "stop"  # the recorder, the bridge
        set_on_failure(node, "continue" if keep_going and policy == "stop" else policy)
    runtime_config = config.runtime
    from aiorobot._core._transport import make_transport

    options = runtime_options(config)  # the Runtime arguments set by the [runtime] table
    # a multi-process graph (no zenoh_config of its own): the processes meet at the supervisor's endpoint
    if group.endpoints and not runtime_config.zenoh_config:
        options["transport"] = make_transport(
            "zenoh", domain_id=runtime_config.domain_id, **group.endpoints, **zenoh_options(config)
        )
    async with Runtime(**options) as rt:
        # Signal handlers stay installed until the runtime has fully shut down: a second
        # Ctrl-C abandons what is blocked, a first one past shutdown_timeout too.
        if runtime_config.strict_qos:  # the graph as written cannot connect: refuse it whole
            for problem in rt.check_qos([node for node, _ in nodes]):
                owners = {problem.publisher_node, problem.subscription_node}
                index = max(i for i, (n, _) in enumerate(nodes) if n.get_fully_qualified_name() in owners)
                table = tables[index]
                raise ConfigError(
                    config.path,
                    table.key if table is not None else "record" if index == 0 else "foxglove",
                    f"runtime.strict_qos is set and {problem}",
                )
        rt.add_nodes(nodes)
        await group.start(rt)
        display = StatusDisplay(
            [node for node, _ in nodes], period_sec=status_period_sec, on_stream_closed=rt.shutdown
        )
        async with display:
            await rt.spin(duration_sec=duration_sec)
        group.terminate()  # the children shut down while this process does
    return _outcome(rt)


def _outcome(rt: Runtime) -> int:
    """Print what went wrong during the run; 1 if a node failed to start or a callback raised."""
    from aiorobot._core._watchdog import EXIT_SHUTDOWN_TIMEOUT

    stats = rt.statistics()
    lines = []
    for fqn in stats["failed_starts"]:
        lines.append(f"  {fqn}: failed to start (on_start raised)")
    for (fqn, entity), count in sorted(stats["failures"].items()):
        if entity == "on_start" and fqn in stats["failed_starts"]:
            continue
        lines.append(f"  {fqn}: {entity} raised {count} time{'s' if count != 1 else ''}")
    for (loop, fqn, entity), count in sorted(stats["stalls"].items()):
        lines.append(f"  {fqn}: {entity} stalled the {loop} loop {count} time{'s' if count != 1 else ''}")
    if lines:
        print("failures:\n" + "\n".join(lines), file=sys.stderr)
    if stats["late_periods"]:
        causes = "".join(f"\n  {c.describe()}" for c in stats["culprits"])
        print(
            f"late priority periods: {stats['late_periods']} started more than "
            f"{(rt.late_threshold or 0) * 1000:g} ms after their deadline; top causes:{causes}",
            file=sys.stderr,
        )
    if rt.abandoned:
        print("abandoned at shutdown: " + "; ".join(rt.abandoned), file=sys.stderr)
        return EXIT_SHUTDOWN_TIMEOUT
    return EXIT_FAILED if stats["failed_starts"] or stats["failures"] else 0
