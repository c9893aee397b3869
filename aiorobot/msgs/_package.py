"""Lazy attribute access for the package modules (``aiorobot.msgs.geometry_msgs`` ...)."""

from __future__ import annotations

import difflib
import sys
from typing import Any

from ._registry import exists, get, package_names

__all__ = ["package_getattr"]


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
