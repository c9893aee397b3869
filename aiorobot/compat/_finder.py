"""The import aliases: ``rclpy``, message packages, ``tf2_ros``, ``message_filters`` -> aiorobot.

A meta path finder placed first on ``sys.meta_path``: ``rclpy[.x]`` resolves to
``aiorobot.compat.rclpy[.x]``, ``tf2_ros``/``tf2_geometry_msgs``/``message_filters``/``cv_bridge``/
``nav2_simple_commander`` to their aiorobot modules, and ``<pkg>.msg|srv|action`` to module views of
``aiorobot.msgs`` for every package aiorobot has interfaces of.
"""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.machinery
import sys
import types
import warnings
from typing import Any

from ._missing import MissingInterfaceError, not_provided

__all__ = ["AliasFinder", "install", "uninstall"]

_ALIASES = {
    "rclpy": "aiorobot.compat.rclpy",
    "tf2_ros": "aiorobot.compat.tf2_ros",
    "tf2_geometry_msgs": "aiorobot.compat.tf2_geometry_msgs",
    "message_filters": "aiorobot.message_filters",
    "sensor_msgs_py": "aiorobot.compat.sensor_msgs_py",
    "cv_bridge": "aiorobot.compat.cv_bridge",
    "nav2_simple_commander": "aiorobot.compat.nav2_simple_commander",
}
#: rclpy modules aiorobot lacks: importing one names it.
_MISSING_MODULES = frozenset(
    {
        "rclpy.waitable", "rclpy.type_support",
        "rclpy.parameter_service",
        "rclpy.expand_topic_name", "rclpy.validate_topic_name",
        "rclpy.validate_node_name", "rclpy.validate_namespace", "rclpy.constants", "rclpy.type_hash",
        "rclpy.time_source",
    }
)

#: rclpy modules rclpy itself warns about on import, and its words.
_DEPRECATED_MODULES = {"rclpy.qos_event": "importing 'qos_event' is deprecated; import 'event_handler' instead"}


def _msg_packages() -> frozenset[str]:
    from ..msgs._registry import all_names

    return frozenset(name.split("/", 1)[0] for name in all_names())


class _Existing(importlib.abc.Loader):
    """Loads an alias: hands back the already imported target module, its own spec kept."""

    def __init__(self, module: types.ModuleType) -> None:
        self.module = module
        self.spec = getattr(module, "__spec__", None)

    def create_module(self, spec: importlib.machinery.ModuleSpec) -> types.ModuleType:
        return self.module

    def exec_module(self, module: types.ModuleType) -> None:
        if self.spec is not None:
            module.__spec__ = self.spec


def _interface_module(package: str, kind: str) -> types.ModuleType:
    from ..msgs._registry import exists, get, package_names

    fullname = f"{package}.{kind}"
    module = types.ModuleType(fullname, f"ROS 2 {kind} types of {package}, from aiorobot.msgs")
    names = sorted(n for n in package_names(package) if exists(f"{package}/{kind}/{n}"))
    module.__all__ = names  # type: ignore[attr-defined]

    def __getattr__(name: str) -> Any:
        if name in names or exists(f"{package}/{kind}/{name}"):  # registered after the import
            cls = get(f"{package}/{kind}/{name}")
            setattr(module, name, cls)
            return cls
        if name.startswith("_"):
            raise AttributeError(f"module {fullname!r} has no attribute {name!r}")
        raise missing_interface(package, kind, name)

    module.__getattr__ = __getattr__  # type: ignore[attr-defined]
    return module


def missing_interface(package: str, kind: str, name: str) -> MissingInterfaceError:
    """The one-line error for ``from <package>.<kind> import <name>`` of an unknown type."""
    import difflib

    from ..msgs._registry import exists, package_names

    fullname = f"{package}.{kind}"
    names = [n for n in package_names(package) if exists(f"{package}/{kind}/{n}")]
    close = difflib.get_close_matches(name, names, n=3)
    hint = f" (did you mean {', '.join(close)}?)" if close else ""
    return MissingInterfaceError(
        f"cannot import name {name!r} from {fullname!r}: aiorobot has no {package}/{kind}/{name}{hint}; "
        f"for your own or a newer {package}, pass its folder with --interfaces DIR",
        name=fullname,
    )


def missing_package(package: str) -> MissingInterfaceError:
    """The one-line error for ``from <package>.msg|srv|action import ...`` of an unknown package."""
    return MissingInterfaceError(
        f"no interface package {package!r}: aiorobot has ROS 2 Jazzy's standard ones; pass the folder of "
        f"{package} (its package.xml, msg/, srv/, action/) with `aiorobot exec --interfaces DIR` "
        f"or in AIOROBOT_INTERFACES",
        name=package,
    )


class AliasFinder(importlib.abc.MetaPathFinder):
    def __init__(self) -> None:
        self._packages: frozenset[str] | None = None
        self._generation = -1

    def packages(self) -> frozenset[str]:
        """The ROS packages aiorobot has interfaces of, registered ones included."""
        from ..msgs._registry import generation

        if self._packages is None or self._generation != generation():
            self._generation = generation()
            self._packages = _msg_packages()
        return self._packages

    def find_spec(self, fullname: str, path: Any = None, target: Any = None) -> importlib.machinery.ModuleSpec | None:
        top, _, rest = fullname.partition(".")
        if top in _ALIASES:
            if fullname in _MISSING_MODULES or any(fullname.startswith(m + ".") for m in _MISSING_MODULES):
                raise not_provided(fullname)
            target_name = _ALIASES[top] + ("." + rest if rest else "")
            if fullname in _DEPRECATED_MODULES:
                warnings.warn(_DEPRECATED_MODULES[fullname], UserWarning, stacklevel=2)
            try:
                module = importlib.import_module(target_name)
            except ModuleNotFoundError as err:
                if err.name == target_name:
                    raise not_provided(fullname) from None
                raise
            return importlib.util.spec_from_loader(fullname, _Existing(module), is_package=hasattr(module, "__path__"))
        if top in self.packages():
            if not rest:
                module = types.ModuleType(top, f"ROS 2 package {top}, from aiorobot.msgs")
                module.__path__ = []  # type: ignore[attr-defined]
                return importlib.util.spec_from_loader(fullname, _Existing(module), is_package=True)
            if rest in ("msg", "srv", "action"):
                return importlib.util.spec_from_loader(fullname, _Existing(_interface_module(top, rest)))
        return None


_finder: AliasFinder | None = None


def install() -> AliasFinder:
    """Put the aliases first on ``sys.meta_path`` (idempotent)."""
    global _finder
    import importlib.util  # noqa: F401  (used by find_spec)

    if _finder is None:
        _finder = AliasFinder()
        _finder.packages()  # before the finder is in place: computing it imports modules
    if _finder not in sys.meta_path:
        sys.meta_path.insert(0, _finder)
    return _finder


def uninstall() -> None:
    """Remove the aliases and forget the modules imported through them."""
    global _finder
    if _finder is not None and _finder in sys.meta_path:
        sys.meta_path.remove(_finder)
    packages = _finder.packages() if _finder is not None else frozenset()
    for name in list(sys.modules):
        if name.partition(".")[0] in _ALIASES or name.partition(".")[0] in packages:
            del sys.modules[name]
