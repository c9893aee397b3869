"""``aiorobot.launch``: graph files (``aiorobot run``'s TOML) read, checked and built into nodes.

:func:`load_config` reads and checks a file into a frozen :class:`GraphConfig` (it imports no
user code); :func:`build_nodes` imports the node classes and constructs the nodes;
:func:`open_runtime` gives a :class:`~aiorobot.Runtime` that runs the file. Every problem is a
:class:`ConfigError`: one line naming the file, the key and what was expected and found.

This is an application layer: the core never imports it. Importing it installs the loader
behind ``Runtime(config=...)`` (``aiorobot.Runtime`` imports it for that).
"""

from __future__ import annotations

from .._core._runtime import install_config_loader
from ._build import build_nodes, node_configs
from ._config import (
    MAIN_PROCESS,
    ConfigError,
    FoxgloveConfig,
    GraphConfig,
    NodeConfig,
    ProcessConfig,
    RecordConfig,
    RuntimeConfig,
    load_config,
    parse_config,
)
from ._open import config_loader, open_runtime, runtime_options

__all__ = [
    "MAIN_PROCESS",
    "ConfigError",
    "FoxgloveConfig",
    "GraphConfig",
    "NodeConfig",
    "ProcessConfig",
    "RecordConfig",
    "RuntimeConfig",
    "build_nodes",
    "load_config",
    "node_configs",
    "open_runtime",
    "parse_config",
    "runtime_options",
]

install_config_loader(config_loader)
