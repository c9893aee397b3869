"""tf2_ros's ``BufferInterface`` and the registries ``transform`` looks message types up in.

``tf2_geometry_msgs`` registers its ``do_transform_*`` functions here on import, as upstream;
``buffer.transform(msg, frame)`` finds the function by the message's class.
"""

from __future__ import annotations

import copy
from collections.abc import Callable
from typing import Any, ClassVar

from ..._core._time import Duration

__all__ = [
    "BufferInterface",
    "ConvertRegistration",
    "NotImplementedException",
    "Stamped",
    "TransformRegistration",
    "TypeException",
    "convert",
]


class TypeException(Exception):
    """An object whose type has no registered transform or conversion (tf2_ros's)."""

    def __init__(self, errstr: str) -> None:
        super().__init__(errstr)
        self.errstr = errstr


class NotImplementedException(Exception):
    """A ``BufferInterface`` subclass lacks ``lookup_transform`` / ``can_transform`` (tf2_ros's)."""

    def __init__(self) -> None:
        self.errstr = "CanTransform or LookupTransform not implemented"
        super().__init__(self.errstr)


def _not_supported(key: Any) -> TypeException:
    name = getattr(key, "__msgtype__", None) or getattr(key, "__name__", str(key))
    return TypeException(
        f"Type {name} is not loaded or supported; import tf2_geometry_msgs to register the "
        "geometry_msgs types (PointStamped, Vector3Stamped, PoseStamped, PoseWithCovarianceStamped, "
        "PolygonStamped)"
    )


class TransformRegistration:
    """Message class -> ``do_transform(msg, transform_stamped)``, shared by every instance (as upstream)."""

    _type_map: ClassVar[dict[Any, Callable[[Any, Any], Any]]] = {}

    def add(self, key: Any, callback: Callable[[Any, Any], Any]) -> None:
        TransformRegistration._type_map[key] = callback

    def get(self, key: Any) -> Callable[[Any, Any], Any]:
        try:
            return TransformRegistration._type_map[key]
        except KeyError:
            raise _not_supported(key) from None

    def print_me(self) -> None:
        print(TransformRegistration._type_map)


class ConvertRegistration:
    """Conversions between message classes and other representations, shared as upstream."""

    _to_msg_map: ClassVar[dict[Any, Callable[[Any], Any]]] = {}
    _from_msg_map: ClassVar[dict[Any, Callable[[Any], Any]]] = {}
    _convert_map: ClassVar[dict[Any, Callable[[Any], Any]]] = {}

    def add_from_msg(self, key: Any, callback: Callable[[Any], Any]) -> None:
        ConvertRegistration._from_msg_map[key] = callback

    def add_to_msg(self, key: Any, callback: Callable[[Any], Any]) -> None:
        ConvertRegistration._to_msg_map[key] = callback

    def add_convert(self, key: tuple[Any, Any], callback: Callable[[Any], Any]) -> None:
        ConvertRegistration._convert_map[key] = callback

    @staticmethod
    def _get(table: dict[Any, Callable[[Any], Any]], key: Any) -> Callable[[Any], Any]:
        try:
            return table[key]
        except KeyError:
            raise _not_supported(key) from None

    def get_from_msg(self, key: Any) -> Callable[[Any], Any]:
        return self._get(ConvertRegistration._from_msg_map, key)

    def get_to_msg(self, key: Any) -> Callable[[Any], Any]:
        return self._get(ConvertRegistration._to_msg_map, key)

    def get_convert(self, key: tuple[Any, Any]) -> Callable[[Any], Any]:
        return self._get(ConvertRegistration._convert_map, key)


def convert(a: Any, b_type: Any) -> Any:
    """``a`` as an object of ``b_type``: a direct conversion, a copy, or via the message (tf2_ros's)."""
    c = ConvertRegistration()
    try:
        return c.get_convert((type(a), b_type))(a)
    except TypeException:
        if type(a) is b_type:
            return copy.deepcopy(a)
        return c.get_from_msg(b_type)(c.get_to_msg(type(a))(a))


def Stamped(obj: Any, stamp: Any, frame_id: str) -> Any:  # noqa: N802 - tf2_ros's name
    """Give ``obj`` a ``header`` with ``stamp`` and ``frame_id`` (tf2_ros's)."""
    from aiorobot.msgs.std_msgs import Header

    obj.header = Header(frame_id=frame_id, stamp=stamp)
    return obj


class BufferInterface:
    """tf2_ros's abstract buffer: ``transform`` / ``transform_full`` on top of the lookups."""

    def __init__(self) -> None:
        self.registration = TransformRegistration()

    def transform(
        self, object_stamped: Any, target_frame: str, timeout: Any = Duration(), new_type: Any = None
    ) -> Any:
        """``object_stamped`` expressed in ``target_frame`` at its ``header.stamp``, waiting up to ``timeout``."""
        do_transform = TransformRegistration().get(type(object_stamped))
        res = do_transform(
            object_stamped,
            self.lookup_transform(
                target_frame, object_stamped.header.frame_id, object_stamped.header.stamp, timeout
            ),
        )
        return res if new_type is None else convert(res, new_type)

    def transform_full(
        self, object_stamped: Any, target_frame: str, target_time: Any, fixed_frame: str,
        timeout: Any = Duration(), new_type: Any = None,
    ) -> Any:
        """As `transform`, into ``target_frame`` at ``target_time`` through ``fixed_frame``."""
        do_transform = TransformRegistration().get(type(object_stamped))
        res = do_transform(
            object_stamped,
            self.lookup_transform_full(
                target_frame, target_time, object_stamped.header.frame_id, object_stamped.header.stamp,
                fixed_frame, timeout,
            ),
        )
        return res if new_type is None else convert(res, new_type)

    def lookup_transform(self, target_frame: str, source_frame: str, time: Any, timeout: Any = Duration()) -> Any:
        raise NotImplementedException()

    def lookup_transform_full(
        self, target_frame: str, target_time: Any, source_frame: str, source_time: Any, fixed_frame: str,
        timeout: Any = Duration(),
    ) -> Any:
        raise NotImplementedException()

    def can_transform(self, target_frame: str, source_frame: str, time: Any, timeout: Any = Duration()) -> bool:
        raise NotImplementedException()

    def can_transform_full(
        self, target_frame: str, target_time: Any, source_frame: str, source_time: Any, fixed_frame: str,
        timeout: Any = Duration(),
    ) -> bool:
        raise NotImplementedException()
