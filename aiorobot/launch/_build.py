"""The building half of the config loader: import node classes and construct the nodes.

:func:`build_nodes` turns a validated :class:`~aiorobot.launch.GraphConfig` into node
objects, checking everything that needs the classes themselves (importable module and
class, an ``aiorobot.Node`` subclass, declared and well-typed parameters, unique names)
before anything is started. Problems raise :class:`~aiorobot.launch.ConfigError`.
"""

from __future__ import annotations

import difflib
import importlib
import inspect
import pkgutil
import sys
from types import ModuleType
from typing import TYPE_CHECKING, Any

from ._config import MAIN_PROCESS, ConfigError, GraphConfig, NodeConfig
from .._core._errors import InvalidParameterValueError

if TYPE_CHECKING:
    from aiorobot import Node

__all__ = ["build_nodes", "import_node_class", "node_configs"]


def build_nodes(config: GraphConfig, process: str = MAIN_PROCESS) -> list[tuple[Node, str]]:
    """Construct the nodes of ``config`` that run in ``process`` (nothing is started).

    The folder holding the config file is put on ``sys.path`` (first) so that
    ``use = "my_nodes:Talker"`` finds ``my_nodes.py`` beside the file.

    For the main process (``aiorobot run`` itself) every node of the file is constructed,
    so that a problem in any process is reported before any process starts; the nodes
    of the other processes are then dropped (their child processes construct their own).
    The ``[record]`` recorder and the Foxglove bridge run in the main process.

    Returns
    -------
    list of (Node, str)
        Each node of ``process`` with its executor name (``"main"`` or ``"priority"``), in file order.

    Raises
    ------
    ConfigError
        The first problem found; no node has been added to any runtime.
    """
    base_dir = str(config.base_dir)
    if base_dir not in sys.path:
        sys.path.insert(0, base_dir)
    main = process == MAIN_PROCESS
    built: list[tuple[Node, str]] = []
    if config.record is not None and main:  # first, so it taps every publisher before its first message
        built.append((_recorder(config), "main"))
    owners: dict[str, int] = {}
    for node_config in config.nodes:
        if not main and node_config.process != process:
            continue
        node = _construct(config, node_config)
        fqn = node.get_fully_qualified_name()
        if fqn in owners:
            raise ConfigError(
                config.path,
                f"{node_config.key}.name",
                f'expected a unique node name, found "{fqn}" again (nodes[{owners[fqn]}] is '
                f"already called that); set a different name or namespace",
            )
        owners[fqn] = node_config.index
        if node_config.process == process:
            built.append((node, node_config.executor))
    if config.foxglove is not None and main:
        from aiorobot.foxglove import FoxgloveBridge

        fox = config.foxglove
        built.append((FoxgloveBridge(host=fox.host, port=fox.port, max_large_hz=fox.max_large_hz,
                                     asset_roots=list(fox.asset_roots)), "main"))
    return built


def node_configs(config: GraphConfig, nodes: list[tuple[Node, str]], process: str = MAIN_PROCESS) -> list[NodeConfig | None]:
    """The ``[[nodes]]`` table each of ``build_nodes(config, process)``'s nodes came from, in the
    same order; None for the ``[record]`` recorder and the Foxglove bridge, which no table names."""
    tables = iter([n for n in config.nodes if n.process == process])
    main = process == MAIN_PROCESS
    out: list[NodeConfig | None] = []
    for index, (node, _) in enumerate(nodes):
        extra = (config.record is not None and main and index == 0) or (
            config.foxglove is not None and main and index == len(nodes) - 1
        )
        out.append(None if extra else next(tables))
    return out


def _recorder(config: GraphConfig) -> Node:
    """The ``[record]`` table's Recorder node; a bag directory that exists already is a config error."""
    from aiorobot.bag import BagError, Recorder

    rec = config.record
    assert rec is not None
    try:
        return Recorder(
            path=rec.path,
            topics=list(rec.topics),
            exclude=rec.exclude,
            compression=rec.compression,
            max_bag_size=rec.max_bag_size,
            max_bag_duration=rec.max_bag_duration,
            max_cache_size=rec.max_cache_size,
        )
    except BagError as err:
        raise ConfigError(config.path, "record.path", str(err)) from None


def import_node_class(config: GraphConfig, node_config: NodeConfig) -> type[Node]:
    """Import the class named by ``node_config.use`` and check that it is a Node subclass."""
    from aiorobot import Node

    key = f"{node_config.key}.use"
    module = _import_module(config, key, node_config.module_name)
    target: Any = module
    for part in node_config.class_name.split("."):
        if not hasattr(target, part):
            candidates = [n for n in dir(target) if not n.startswith("_")]
            nodes = [n for n in candidates if _is_node_class(getattr(target, n, None), Node)]
            close = difflib.get_close_matches(part, nodes, n=1) or difflib.get_close_matches(
                part, candidates, n=1
            )
            hint = f' (did you mean "{close[0]}"?)' if close else ""
            owner = f'module "{node_config.module_name}"' if target is module else f'"{target.__qualname__}"'
            raise ConfigError(config.path, key, f'{owner} has no class "{part}"{hint}')
        target = getattr(target, part)
    if not _is_node_class(target, Node):
        if inspect.isclass(target):
            kind = "a class not derived from aiorobot.Node"
        else:
            kind = f"a {type(target).__name__}"
        raise ConfigError(
            config.path,
            key,
            f'expected an aiorobot.Node subclass, found "{node_config.use}" ({kind})',
        )
    return target


def _import_module(config: GraphConfig, key: str, module_name: str) -> ModuleType:
    try:
        return importlib.import_module(module_name)
    except ModuleNotFoundError as err:
        missing = err.name or ""
        if missing and (module_name == missing or module_name.startswith(missing + ".")):
            raise ConfigError(
                config.path, key, _module_not_found(module_name, missing, config)
            ) from None
        raise ConfigError(
            config.path, key, f'importing module "{module_name}" failed: {_describe(err)}'
        ) from None
    except Exception as err:  # the user's module raised while being imported
        raise ConfigError(
            config.path, key, f'importing module "{module_name}" failed: {_describe(err)}'
        ) from None


def _module_not_found(module_name: str, missing: str, config: GraphConfig) -> str:
    """Explain which part of a dotted module path is missing, with a close existing name."""
    parent, _, leaf = missing.rpartition(".")
    if parent:
        try:
            package = importlib.import_module(parent)
            siblings = [m.name for m in pkgutil.iter_modules(getattr(package, "__path__", []))]
        except Exception:  # noqa: BLE001 - a suggestion is a nicety, never an error
            siblings = []
        where = ""
    else:  # a top-level module: suggest from the config's folder
        siblings = [m.name for m in pkgutil.iter_modules([str(config.base_dir)])]
        where = f" on the Python path or in {config.base_dir}"
    close = difflib.get_close_matches(leaf, siblings, n=1)
    hint = f' (did you mean "{parent + "." if parent else ""}{close[0]}"?)' if close else ""
    found = f'module "{module_name}" was not found'
    if missing != module_name:
        found += f': there is no "{missing}"'
    return f"expected an importable module{where}, but {found}{hint}"


def _construct(config: GraphConfig, node_config: NodeConfig) -> Node:
    cls = import_node_class(config, node_config)
    kwargs: dict[str, Any] = {}
    if node_config.parameters:
        kwargs["parameter_overrides"] = {
            name: list(value) if isinstance(value, tuple) else value
            for name, value in node_config.parameters.items()
        }
    remappings: dict[str, str] = {}
    if node_config.name is not None:
        remappings["__node"] = node_config.name
    if node_config.namespace is not None:
        remappings["__ns"] = node_config.namespace
    remappings.update(node_config.remap)
    if remappings:
        kwargs["remappings"] = remappings
    files = [f for f in (config.runtime.parameters_file, node_config.parameters_file) if f]
    if files:  # sections matched to the node's name, under the inline parameters
        kwargs["cli_args"] = ["--ros-args", *(arg for f in files for arg in ("--params-file", f))]
    _check_signature(config, node_config, cls, kwargs)
    try:
        node = cls(**kwargs)
    except InvalidParameterValueError as err:
        key = _parameter_key(node_config, err.name, config)
        reason = err.reason if key.endswith(f".{err.name}") else f"parameter {err.name!r}: {err.reason}"
        raise ConfigError(config.path, key, reason) from None
    except Exception as err:  # noqa: BLE001 - any constructor failure is a config problem
        raise ConfigError(
            config.path,
            node_config.key,
            f'constructing "{node_config.use}" failed: {_describe(err)}',
        ) from None
    _check_kwargs_reached_node(config, node_config, cls, node, kwargs)
    unclaimed = sorted(node.unclaimed_parameter_overrides())
    if unclaimed:
        name = unclaimed[0]
        declared = _declared_parameters(node)
        close = difflib.get_close_matches(name, declared, n=1)
        hint = f' (did you mean "{close[0]}"?)' if close else ""
        known = f"; it declares: {', '.join(declared)}" if declared else "; it declares none"
        raise ConfigError(
            config.path,
            _parameter_key(node_config, name),
            f'expected a parameter declared by node "{node.get_fully_qualified_name()}" '
            f"({cls.__name__}), found an undeclared one{hint}{known}",
        )
    if node_config.log_level is not None:
        node.get_logger().set_level(node_config.log_level)
    return node


def _check_kwargs_reached_node(
    config: GraphConfig, node_config: NodeConfig, cls: type, node: Node, kwargs: dict[str, Any]
) -> None:
    """The built node carries the configured name, namespace, overrides and remappings.

    A constructor that accepts ``**kwargs`` but does not pass them on to ``Node.__init__``
    would otherwise run with none of its configuration.
    """
    dropped = []
    if node_config.name is not None and node.get_name() != node_config.name:
        dropped.append(f"name {node_config.name!r} (the node is named {node.get_name()!r})")
    if node_config.namespace is not None and node.get_namespace() != node_config.namespace:
        dropped.append(f"namespace {node_config.namespace!r} (the node has {node.get_namespace()!r})")
    overrides = getattr(node._parameters, "overrides", {})
    if any(name not in overrides for name in kwargs.get("parameter_overrides", {})):
        dropped.append("parameters")
    if any(node._remappings.get(k) != v for k, v in node_config.remap.items()):
        dropped.append("remap")
    if dropped:
        raise ConfigError(
            config.path,
            node_config.key,
            f"{cls.__name__} ignored its configured {', '.join(dropped)}: its constructor must pass "
            f'**kwargs to Node.__init__ (write "def __init__(self, **kw): super().__init__("name", **kw)")',
        )


def _check_signature(
    config: GraphConfig, node_config: NodeConfig, cls: type, kwargs: dict[str, Any]
) -> None:
    """A class whose ``__init__`` cannot take the keywords gets a hint on how to write it."""
    if not kwargs:
        return
    try:
        signature = inspect.signature(cls)
    except (TypeError, ValueError):
        return
    params = signature.parameters.values()
    if any(p.kind is inspect.Parameter.VAR_KEYWORD for p in params):
        return
    missing = [k for k in kwargs if k not in signature.parameters]
    if missing:
        raise ConfigError(
            config.path,
            node_config.key,
            f"expected {cls.__name__}.__init__ to accept {' and '.join(missing)} (write "
            f'"def __init__(self, **kw): super().__init__("name", **kw)"), found '
            f"{cls.__name__}{signature.replace(return_annotation=inspect.Signature.empty)}",
        )


def _declared_parameters(node: Node) -> list[str]:
    lister = getattr(node, "list_parameters", None)
    if lister is None:
        return []
    try:
        names = lister()
    except Exception:  # noqa: BLE001 - a suggestion is a nicety
        return []
    names = getattr(names, "names", names)
    return sorted(str(n) for n in names)


def _parameter_key(node_config: NodeConfig, name: str, config: GraphConfig | None = None) -> str:
    """The key that gave ``name`` its value: the node's ``parameters`` table, else the parameter
    file that did (the message then names that file's key)."""
    if name not in node_config.parameters and config is not None:
        if node_config.parameters_file is not None:
            return f"{node_config.key}.parameters_file"
        if config.runtime.parameters_file is not None:
            return "runtime.parameters_file"
    return f"{node_config.key}.parameters.{name}"


def _is_node_class(obj: Any, node_base: type) -> bool:
    return inspect.isclass(obj) and issubclass(obj, node_base)


def _describe(err: BaseException) -> str:
    text = str(err)
    return f"{type(err).__name__}: {text}" if text else type(err).__name__
