"""``tf2_ros`` on aiorobot (installed by ``aiorobot exec``): Buffer, TransformListener, broadcasters.

The buffer, the maths and the exceptions are :mod:`aiorobot.tf`'s, under tf2_ros's names and
signatures; ``import tf2_geometry_msgs`` registers the geometry_msgs types for
``buffer.transform``. See docs/rclpy-compat.md for what differs and what is missing.
"""

from __future__ import annotations

from typing import Any

from ...tf import (
    ConnectivityException,
    ExtrapolationException,
    InvalidArgumentException,
    LookupException,
    TransformException,
)
from .._missing import module_getattr
from ._broadcasters import StaticTransformBroadcaster, TransformBroadcaster
from ._buffer import Buffer, BufferCore, TimeoutException
from ._interface import (
    BufferInterface,
    ConvertRegistration,
    NotImplementedException,
    Stamped,
    TransformRegistration,
    TypeException,
    convert,
)
from ._listener import TransformListener

__all__ = [
    "Buffer",
    "BufferCore",
    "BufferInterface",
    "ConnectivityException",
    "ConvertRegistration",
    "ExtrapolationException",
    "InvalidArgumentException",
    "LookupException",
    "NotImplementedException",
    "Stamped",
    "StaticTransformBroadcaster",
    "TimeoutException",
    "TransformBroadcaster",
    "TransformException",
    "TransformListener",
    "TransformRegistration",
    "TypeException",
    "convert",
]

_SUBMODULES = frozenset(
    {"buffer", "buffer_interface", "transform_listener", "transform_broadcaster", "static_transform_broadcaster"}
)
_missing = module_getattr(__name__, "tf2_ros", {"BufferClient", "buffer_client"})


def __getattr__(name: str) -> Any:
    if name in _SUBMODULES:
        import importlib

        return importlib.import_module(f"{__name__}.{name}")
    return _missing(name)
