"""``tf2_ros.buffer_interface``."""

from . import _interface
from ._interface import *  # noqa: F403 - upstream's module of these names

__all__ = list(_interface.__all__)
