"""``tf2_geometry_msgs.tf2_geometry_msgs`` (upstream's module; the package re-exports it)."""

from . import _transforms
from ._transforms import *  # noqa: F403

__all__ = list(_transforms.__all__)
