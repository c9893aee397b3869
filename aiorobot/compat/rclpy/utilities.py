"""``rclpy.utilities``."""

from __future__ import annotations

import sys
from collections.abc import Sequence

from ..._core._ros_args import strip_ros_args
from . import ok, shutdown, try_shutdown

__all__ = ["ok", "remove_ros_args", "shutdown", "try_shutdown"]


def remove_ros_args(args: Sequence[str] | None = None) -> list[str]:
    return strip_ros_args(sys.argv if args is None else args)
