"""``aiorobot run module:Class [--duration SEC] --ros-args ...``: one node, as ``ros2 run`` runs it.

``--ros-args`` takes ROS 2's arguments (``-p name:=value``, ``-r from:=to``, ``-r __node:=x``,
``-r __ns:=/y``, ``--params-file f.yaml``, ``--log-level LEVEL``; see ``aiorobot._core._ros_args``).
The node class must accept ``**kwargs`` (they reach ``Node.__init__`` as ``cli_args``).
Everything is checked before the runtime starts; a bad argument is one line and status 2.
"""

from __future__ import annotations

import argparse
import asyncio
import importlib
import inspect
import logging
import re
import signal
import sys
from typing import Any

__all__ = ["is_node_spec", "run_node"]

EXIT_USAGE = 2
_SPEC = re.compile(r"^[A-Za-z_][\w.]*:[A-Za-z_][\w.]*$")


def is_node_spec(text: str) -> bool:
    """Whether ``text`` names a node class (``package.module:Class``) rather than a config file."""
    return bool(_SPEC.match(text)) and not text.endswith(".toml")


def run_node(args: argparse.Namespace) -> int:
    """Build the node from ``args.config`` (a ``module:Class``) and ``args.ros_args``; run it."""
    spec = str(args.config)
    ros_args = ["--ros-args", *(args.ros_args or [])]
    from aiorobot._core._ros_args import RosArgsError

    from ._logging import configure_logging

    try:
        configure_logging(_log_level(ros_args))
        node = build_node(spec, ros_args)
    except (_UsageError, RosArgsError) as err:
        print(f"aiorobot run: error: {err}", file=sys.stderr)
        return EXIT_USAGE
    import aiorobot

    try:
        return aiorobot.run(_serve(node, args.duration))
    except KeyboardInterrupt:
        return 130


class _UsageError(Exception):
    pass


def _log_level(ros_args: list[str]) -> str:
    from aiorobot._core._ros_args import parse_ros_args

    return parse_ros_args(ros_args).log_level or "info"


def build_node(spec: str, cli_args: list[str]) -> Any:
    """Import ``spec`` and construct it with ``cli_args``; ``_UsageError`` with one line on any problem."""
    from aiorobot import Node, ParameterError
    from aiorobot.parameters import ParameterFileError
    from aiorobot._core._ros_args import RosArgsError, parse_ros_args

    try:
        parse_ros_args(cli_args)
    except RosArgsError as err:
        raise _UsageError(str(err)) from None
    module_name, _, class_path = spec.partition(":")
    if "" not in sys.path:
        sys.path.insert(0, "")  # modules beside the working directory, as `python -m`
    try:
        target: Any = importlib.import_module(module_name)
    except ModuleNotFoundError as err:
        raise _UsageError(f'expected an importable module in "{spec}", but module "{err.name}" was not found') from None
    except Exception as err:  # noqa: BLE001 - the user's module raised on import
        raise _UsageError(f'importing module "{module_name}" failed: {type(err).__name__}: {err}') from None
    for part in class_path.split("."):
        if not hasattr(target, part):
            raise _UsageError(f'module "{module_name}" has no class "{class_path}"')
        target = getattr(target, part)
    if not (inspect.isclass(target) and issubclass(target, Node)):
        raise _UsageError(f'expected an aiorobot.Node subclass, found "{spec}" ({type(target).__name__})')
    try:
        params = list(inspect.signature(target).parameters.values())
        accepts = any(p.kind is inspect.Parameter.VAR_KEYWORD or p.name == "cli_args" for p in params)
    except (TypeError, ValueError):
        accepts = True
    if not accepts and len(cli_args) > 1:
        raise _UsageError(
            f'"{spec}" cannot take ROS arguments: give its __init__ **kwargs and pass them to Node.__init__'
        )
    try:
        return target(cli_args=cli_args) if accepts else target()
    except FileNotFoundError as err:
        raise _UsageError(f"--params-file: no such file {err.filename!r}") from None
    except (RosArgsError, ParameterFileError, ParameterError) as err:
        raise _UsageError(str(err)) from None
    except Exception as err:  # noqa: BLE001 - a constructor failure is the user's to read, in one line
        raise _UsageError(f'constructing "{spec}" failed: {type(err).__name__}: {err}') from None


async def _serve(node: Any, duration_sec: float | None) -> int:
    from aiorobot import Runtime

    loop = asyncio.get_running_loop()
    signals = (signal.SIGINT, signal.SIGTERM)
    try:
        async with Runtime(handle_signals=False) as rt:
            for signum in signals:
                loop.add_signal_handler(signum, _on_signal, rt, signum)
            rt.add_node(node)
            await rt.spin(duration_sec=duration_sec)
    finally:
        for signum in signals:
            loop.remove_signal_handler(signum)
    return 0


def _on_signal(rt: Any, signum: int) -> None:
    if not rt.is_shutdown:
        logging.getLogger("aiorobot.cli").info(f"{signal.Signals(signum).name} received: shutting down")
    rt.shutdown()
