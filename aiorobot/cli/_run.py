"""``aiorobot run [CONFIG.toml] [--duration SEC]``: run a graph of nodes from a config file.

Everything is loaded, imported, constructed and checked before the runtime starts, so a
bad file starts no node. SIGINT and SIGTERM shut the runtime down cleanly (exit 0).
"""

from __future__ import annotations

import argparse
import asyncio
import logging
import signal
import sys
from pathlib import Path
from typing import TYPE_CHECKING

from ._parser import positive_seconds

if TYPE_CHECKING:
    from aiorobot import Runtime
    from aiorobot._config import GraphConfig

__all__ = ["add_arguments", "main"]

#: exit status for a bad configuration (as for bad command-line arguments)
EXIT_CONFIG_ERROR = 2
#: exit status when interrupted before the runtime could install its signal handlers
EXIT_INTERRUPTED = 130


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.description = (
        "Run a graph of nodes described by a TOML file: a [runtime] table and one [[nodes]] "
        "table per node (use = \"module:Class\"; the file's folder is importable). "
        "Without a file, run the bundled example: an IMU publisher on the main loop and a "
        "rate/latency monitor on the priority loop. Ctrl-C stops cleanly."
    )
    parser.add_argument(
        "config",
        nargs="?",
        type=Path,
        metavar="CONFIG.toml",
        help="graph configuration file (default: the bundled example)",
    )
    parser.add_argument(
        "--duration",
        type=positive_seconds,
        metavar="SEC",
        help="stop after this many seconds (default: run until Ctrl-C or SIGTERM)",
    )
    parser.add_argument(
        "--status-period",
        type=positive_seconds,
        default=1.0,
        metavar="SEC",
        help="seconds between status lines (default: 1)",
    )


def main(args: argparse.Namespace) -> int:
    from aiorobot._config import ConfigError, load_config

    if args.config is None:
        from aiorobot.examples import DEFAULT_CONFIG

        config_path: Path = DEFAULT_CONFIG
    else:
        config_path = args.config
    try:
        config = load_config(config_path)
    except ConfigError as err:
        print(err, file=sys.stderr)
        return EXIT_CONFIG_ERROR

    import aiorobot

    from ._logging import configure_logging

    configure_logging(config.runtime.log_level)
    try:
        return aiorobot.run(_serve(config, args.duration, args.status_period))
    except ConfigError as err:
        print(err, file=sys.stderr)
        return EXIT_CONFIG_ERROR
    except KeyboardInterrupt:  # before the signal handlers were in place
        return EXIT_INTERRUPTED


async def _serve(config: GraphConfig, duration_sec: float | None, status_period_sec: float) -> int:
    from aiorobot import Runtime
    from aiorobot._config import ConfigError
    from aiorobot._config_build import build_nodes

    from ._status import StatusDisplay

    nodes = build_nodes(config)  # raises ConfigError before anything starts
    runtime_config = config.runtime
    loop = asyncio.get_running_loop()
    signals = (signal.SIGINT, signal.SIGTERM)
    try:
        async with Runtime(
            transport=runtime_config.transport,
            domain_id=runtime_config.domain_id,
            use_sim_time=runtime_config.use_sim_time,
            strict_qos=runtime_config.strict_qos,
            priority_realtime=runtime_config.priority_realtime,
            debug_messages=runtime_config.debug_messages,
            handle_signals=False,  # ours stay installed until the runtime has fully shut down
        ) as rt:
            for signum in signals:
                loop.add_signal_handler(signum, _on_signal, rt, signum)
            if runtime_config.strict_qos:  # the graph as written cannot connect: refuse it whole
                for problem in rt.check_qos([node for node, _ in nodes]):
                    owners = {problem.publisher_node, problem.subscription_node}
                    index = max(i for i, (n, _) in enumerate(nodes) if n.get_fully_qualified_name() in owners)
                    raise ConfigError(
                        config.path,
                        config.nodes[index].key,
                        f"runtime.strict_qos is set and {problem}",
                    )
            rt.add_nodes(nodes)
            display = StatusDisplay(
                [node for node, _ in nodes], period_sec=status_period_sec, on_stream_closed=rt.shutdown
            )
            async with display:
                await rt.spin(duration_sec=duration_sec)
    finally:  # kept until the runtime has shut down: a second Ctrl-C must not interrupt that
        for signum in signals:
            loop.remove_signal_handler(signum)
    return 0


def _on_signal(rt: Runtime, signum: int) -> None:
    if not rt.is_shutdown:
        logging.getLogger("aiorobot.cli").info(f"{signal.Signals(signum).name} received: shutting down")
    rt.shutdown()
