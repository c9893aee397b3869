"""``tf2_ros.buffer``."""

from ._buffer import Buffer

__all__ = ["Buffer"]
