"""``rclpy.serialization``: ``serialize_message`` and ``deserialize_message`` on aiorobot's CDR.

The bytes are what rclpy (rmw) gives: little-endian CDR with the 4-byte encapsulation
header, the same bytes a ``raw=True`` subscription receives.
"""

from __future__ import annotations

from typing import Any

from ...msgs import deserialize, serialize
from ...msgs._classgen import Message

__all__ = ["deserialize_message", "serialize_message"]


def serialize_message(message: Any) -> bytes:
    """The CDR bytes of ``message`` (``TypeError`` for anything that is not a message, as rclpy)."""
    if not isinstance(message, Message):
        raise TypeError(
            f"serialize_message: expected a ROS message instance, got {type(message).__name__} {message!r:.80}"
        )
    return serialize(message)


def deserialize_message(serialized_message: bytes, message_type: Any) -> Any:
    """The ``message_type`` instance that ``serialized_message`` (CDR bytes) encodes."""
    if not isinstance(message_type, type) or not issubclass(message_type, Message):
        raise TypeError(
            f"deserialize_message: expected a ROS message type, got {message_type!r:.80}"
        )
    if not isinstance(serialized_message, (bytes, bytearray, memoryview)):
        raise TypeError(
            f"deserialize_message: expected the serialized message as bytes, got "
            f"{type(serialized_message).__name__}"
        )
    return deserialize(serialized_message, message_type)
