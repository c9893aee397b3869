"""Run unmodified rclpy programs on aiorobot: ``aiorobot exec script.py`` or ``python -m aiorobot.compat``.

:func:`install` makes ``rclpy`` (and its submodules), the ROS message packages
(``std_msgs.msg``, ``example_interfaces.srv``, ...), ``tf2_ros``, ``tf2_geometry_msgs``
and ``message_filters`` import from aiorobot; :func:`run_path` runs a script with them.
What is supported, what differs and what is missing: docs/rclpy-compat.md.
"""

from __future__ import annotations

import runpy
import sys
from collections.abc import Callable, Sequence
from typing import Any

from ._finder import install, uninstall
from ._missing import DOCS_URL, NotProvidedError

__all__ = ["DOCS_URL", "NotProvidedError", "install", "resolve_entry_point", "run_entry_point", "run_path", "uninstall"]


def run_path(script: str, args: Sequence[str] = ()) -> None:
    """Run ``script`` as ``__main__`` with ``sys.argv = [script, *args]`` and the aliases installed."""
    import os

    install()
    sys.argv = [script, *args]
    sys.path.insert(0, os.path.dirname(os.path.abspath(script)))
    runpy.run_path(script, run_name="__main__")


def resolve_entry_point(spec: str) -> Callable[[], Any]:
    """The function ``module:function`` names (aliases installed); ``ValueError`` saying what is missing."""
    import importlib

    install()
    module_name, _, attr = spec.partition(":")
    try:
        target: Any = importlib.import_module(module_name)
    except ModuleNotFoundError as err:
        if err.name is not None and (module_name == err.name or module_name.startswith(err.name + ".")):
            raise ValueError(
                f"{spec}: no module named {err.name!r} (is its directory on PYTHONPATH, or the package installed?)"
            ) from None
        raise
    for part in attr.split("."):
        if not hasattr(target, part):
            raise ValueError(f"{spec}: module {module_name!r} has no attribute {attr!r}")
        target = getattr(target, part)
    if not callable(target):
        raise ValueError(f"{spec}: expected a function, found {type(target).__name__} {target!r}")
    return target  # type: ignore[no-any-return]


def run_entry_point(spec: str, args: Sequence[str] = ()) -> int:
    """Call ``module:function`` as a ``console_scripts`` wrapper does (``ros2 run``); its exit status.

    ``sys.argv = [spec, *args]``; the function's return value is the status, as
    ``sys.exit(main())`` makes it (``None`` is 0, a string is printed and gives 1).
    """
    main = resolve_entry_point(spec)
    sys.argv = [spec, *args]
    result = main()
    if result is None:
        return 0
    if isinstance(result, int):
        return result
    print(result, file=sys.stderr)
    return 1
