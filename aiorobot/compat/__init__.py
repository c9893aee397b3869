"""Run unmodified rclpy programs on aiorobot: ``aiorobot exec script.py`` or ``python -m aiorobot.compat``.

:func:`install` makes ``rclpy`` (and its submodules), the ROS message packages
(``std_msgs.msg``, ``example_interfaces.srv``, ...), ``tf2_ros``, ``tf2_geometry_msgs``
and ``message_filters`` import from aiorobot; :func:`run_path` runs a script with them.
What is supported, what differs and what is missing: docs/rclpy-compat.md.
"""

from __future__ import annotations

import runpy
import sys
from collections.abc import Sequence

from ._finder import install, uninstall
from ._missing import DOCS_URL, NotProvidedError

__all__ = ["DOCS_URL", "NotProvidedError", "install", "run_path", "uninstall"]


def run_path(script: str, args: Sequence[str] = ()) -> None:
    """Run ``script`` as ``__main__`` with ``sys.argv = [script, *args]`` and the aliases installed."""
    import os

    install()
    sys.argv = [script, *args]
    sys.path.insert(0, os.path.dirname(os.path.abspath(script)))
    runpy.run_path(script, run_name="__main__")
