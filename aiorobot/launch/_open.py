"""Open a :class:`~aiorobot.Runtime` from a graph file: its ``[runtime]`` table as the runtime's
arguments, its nodes built (and checked) when the runtime is entered.

The core reads no config file: ``Runtime(config=...)`` calls the loader this module
installs (:func:`config_loader`), and :func:`open_runtime` is the call for new code.
"""

from __future__ import annotations

import os
from functools import partial
from typing import TYPE_CHECKING, Any

from .._core._runtime import Runtime
from .._core._transport import make_transport
from ._build import build_nodes
from ._config import GraphConfig, load_config

if TYPE_CHECKING:
    from collections.abc import Callable
    from pathlib import Path

    from .._core._node import Node

__all__ = ["config_loader", "open_runtime", "runtime_options", "zenoh_options"]

#: the arguments of Runtime that a graph file's [runtime] table sets (the keys of runtime_options)
_FILE_SETS = (
    "transport", "domain_id", "use_sim_time", "strict_qos", "priority_realtime", "debug_messages",
    "shutdown_timeout", "stall_threshold", "priority_stall_threshold", "late_threshold",
)


def runtime_options(config: GraphConfig) -> dict[str, Any]:
    """The keyword arguments of :class:`~aiorobot.Runtime` that ``config``'s ``[runtime]`` table sets."""
    rc = config.runtime
    transport: Any = rc.transport
    if rc.zenoh_config or rc.iceoryx2_topics:  # a zenoh session config file (routers, TLS, access control)
        transport = make_transport("zenoh", domain_id=rc.domain_id, config_file=rc.zenoh_config, **zenoh_options(config))
    return {
        "transport": transport,
        "domain_id": rc.domain_id,
        "use_sim_time": rc.use_sim_time,
        "strict_qos": rc.strict_qos,
        "priority_realtime": rc.priority_realtime,
        "debug_messages": rc.debug_messages,
        "shutdown_timeout": rc.shutdown_timeout,
        "stall_threshold": rc.stall_threshold,
        "priority_stall_threshold": rc.priority_stall_threshold,
        "late_threshold": rc.late_threshold,
    }


def zenoh_options(config: GraphConfig) -> dict[str, Any]:
    """The ZenohTransport arguments of ``config``'s ``[runtime]`` table besides its config file."""
    topics = config.runtime.iceoryx2_topics
    return {"iceoryx2_topics": list(topics)} if topics else {}


def open_runtime(config: str | os.PathLike[str] | Path | GraphConfig, **kwargs: Any) -> Runtime:
    """A :class:`~aiorobot.Runtime` (not entered yet) running the graph file ``config``.

    ``async with open_runtime("graph.toml") as rt: await rt.spin()``. The file is read and
    checked now (:class:`~aiorobot.ConfigError`); its nodes are imported, constructed and
    checked on entry, before any of them starts. ``kwargs`` are the runtime's other
    arguments (``handle_signals``, ``process_workers``, ``thread_workers``); one that the
    ``[runtime]`` table sets (``domain_id``, ``use_sim_time``, ...) is a TypeError: write it
    in the file.
    """
    config = _graph_config(config)
    clash = [name for name in _FILE_SETS if name in kwargs]
    if clash:
        raise TypeError(
            f"open_runtime: {', '.join(clash)} is set by the [runtime] table of {config.path}; "
            "set it there, or build the Runtime yourself"
        )
    return Runtime(config=config, **kwargs)


def config_loader(
    config: str | os.PathLike[str] | GraphConfig,
) -> tuple[dict[str, Any], Callable[[], list[tuple[Node, str]]]]:
    """What ``Runtime(config=...)`` calls (installed by :mod:`aiorobot.launch`): the runtime's
    arguments from the file's ``[runtime]`` table, and the builder of its nodes for entry."""
    graph = _graph_config(config)
    if graph.child_processes:
        raise ValueError(
            f"{graph.path}: its nodes run in several processes ({', '.join(graph.child_processes)}); "
            "a Runtime is one process: start the file with aiorobot run"
        )
    return runtime_options(graph), partial(build_nodes, graph)


def _graph_config(config: Any) -> GraphConfig:
    if isinstance(config, GraphConfig):
        return config
    if isinstance(config, (str, os.PathLike)):
        return load_config(os.fspath(config))
    raise TypeError(f"config: expected a graph file path or a GraphConfig, found {config!r}")
