"""tf's exception hierarchy, with tf2's meanings."""

from __future__ import annotations

__all__ = [
    "ConnectivityException",
    "ExtrapolationException",
    "InvalidArgumentException",
    "LookupException",
    "TransformException",
]


class TransformException(Exception):
    """Base of every tf error: catch this to handle any failed lookup."""


class LookupException(TransformException):
    """A frame is unknown, or the tree is invalid (a loop, or a path deeper than 1000 links)."""


class ConnectivityException(TransformException):
    """Both frames exist but belong to trees that are not connected."""


class ExtrapolationException(TransformException):
    """The requested time lies outside the data of a link (no extrapolation is done)."""


class InvalidArgumentException(TransformException):
    """An argument is malformed: an empty or '/'-prefixed frame id, NaN, a bad quaternion."""

