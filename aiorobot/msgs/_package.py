"""Lazy attribute access for the package modules (``aiorobot.msgs.geometry_msgs`` ...).

Packages shipped with aiorobot have a generated module each; packages registered at run
time (:func:`aiorobot.msgs.register_package`) get one from :class:`RegisteredPackageFinder`.
"""

from __future__ import annotations

import difflib
import importlib.abc
import importlib.machinery
import importlib.util
import sys
import types
from typing import Any

from ._registry import all_names, exists, get, package_names

__all__ = ["RegisteredPackageFinder", "install_registered_finder", "package_getattr"]


def package_getattr(module_name: str, package: str, name: str) -> Any:
    """Build, cache in the module and return interface ``name`` of ROS ``package``."""
    if name.startswith("_"):
        raise AttributeError(f"module {module_name!r} has no attribute {name!r}")
    for kind in ("msg", "srv", "action"):
        full = f"{package}/{kind}/{name}"
        if exists(full):
            cls = get(full)
            setattr(sys.modules[module_name], name, cls)
            return cls
    close = difflib.get_close_matches(name, package_names(package), n=3)
    hint = f"; did you mean {', '.join(repr(c) for c in close)}?" if close else ""
    raise AttributeError(f"module {module_name!r} has no interface type {name!r}{hint}")


class _PackageModule(importlib.abc.Loader):
    def __init__(self, package: str) -> None:
        self.package = package

    def create_module(self, spec: importlib.machinery.ModuleSpec) -> types.ModuleType:
        module = types.ModuleType(spec.name, f"ROS 2 interfaces of package {self.package!r} (registered)")
        module.__all__ = package_names(self.package)  # type: ignore[attr-defined]
        package, fullname = self.package, spec.name
        module.__getattr__ = lambda name: package_getattr(fullname, package, name)  # type: ignore[attr-defined]
        return module

    def exec_module(self, module: types.ModuleType) -> None:
        pass


class RegisteredPackageFinder(importlib.abc.MetaPathFinder):
    """``aiorobot.msgs.<pkg>`` for a package registered at run time (last on ``sys.meta_path``)."""

    def find_spec(self, fullname: str, path: Any = None, target: Any = None) -> importlib.machinery.ModuleSpec | None:
        prefix, _, package = fullname.rpartition(".")
        if prefix != __package__ or not package or package.startswith("_"):
            return None
        if not any(n.startswith(f"{package}/") for n in all_names()):
            return None
        return importlib.util.spec_from_loader(fullname, _PackageModule(package))


_finder = RegisteredPackageFinder()


def install_registered_finder() -> None:
    """Append the finder to ``sys.meta_path`` (idempotent): files of shipped packages come first."""
    if _finder not in sys.meta_path:
        sys.meta_path.append(_finder)
