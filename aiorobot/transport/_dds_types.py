"""aiorobot message classes as cyclonedds-python ``IdlStruct`` types, for topics only.

Cyclone needs a type to create a topic: it checks every sample against it and announces it
(XTypes type information) so that peers match. The payload itself never goes through these
classes: aiorobot's CDR (byte-exact with ROS 2's) is handed to the writer as bytes and taken
from the reader as bytes. ROS types are key-less *final* structs, written as XCDR1 (INTEROP §8.3);
nested structs are named ``pkg::msg::dds_::Name_`` like the top-level one.
"""

from __future__ import annotations

import re
import threading
from typing import Any

from ._dds_wire import dds_type, request_type

__all__ = ["UnsupportedTypeError", "idl_struct", "idl_request"]

_lock = threading.Lock()
_cache: dict[tuple[str, str, bool], Any] = {}
_ARRAY = re.compile(r"^(?P<base>.+?)\[(?P<bound><=)?(?P<size>\d*)\]$")


class UnsupportedTypeError(TypeError):
    """A field type cyclonedds-python cannot describe (``wstring``)."""


def _primitives() -> dict[str, Any]:
    from cyclonedds.idl import types as t

    return {
        "bool": bool, "byte": t.byte, "char": t.uint8, "octet": t.byte,
        "int8": t.int8, "uint8": t.uint8, "int16": t.int16, "uint16": t.uint16,
        "int32": t.int32, "uint32": t.uint32, "int64": t.int64, "uint64": t.uint64,
        "float32": t.float32, "float64": t.float64, "string": str,
    }


def _field_type(spec: str, where: str) -> Any:
    from cyclonedds.idl import types as t

    found = _ARRAY.match(spec)
    if found is not None:
        inner = _field_type(found["base"], where)
        size = int(found["size"]) if found["size"] else None
        if found["bound"]:
            return t.sequence[inner, size]
        return t.sequence[inner] if size is None else t.array[inner, size]
    if spec.startswith("string<="):
        return t.bounded_str[int(spec[len("string<="):])]
    if spec.startswith("wstring"):
        raise UnsupportedTypeError(f"{where}: cyclonedds-python has no wstring; this type cannot go over DDS")
    primitive = _primitives().get(spec)
    if primitive is not None:
        return primitive
    from ..msgs import get

    return _struct(get(spec), dds_type(spec))


def _struct(msg_type: Any, typename: str, header: bool = False) -> Any:
    key = (msg_type.__msgtype__, typename, header)
    with _lock:
        cached = _cache.get(key)
    if cached is not None:
        return cached
    from cyclonedds.idl import make_idl_struct
    from cyclonedds.idl import types as t

    fields: dict[str, Any] = {"guid": t.uint64, "seq": t.int64} if header else {}
    for name, spec in msg_type.get_fields_and_field_types().items():
        fields[name] = _field_type(spec, f"{msg_type.__msgtype__}.{name}")
    cls = make_idl_struct(typename.rsplit("::", 1)[-1], typename, fields)
    with _lock:
        return _cache.setdefault(key, cls)


def idl_struct(msg_type: Any) -> Any:
    """The ``IdlStruct`` of a message class, typename ``pkg::msg::dds_::Name_``."""
    return _struct(msg_type, dds_type(msg_type.__msgtype__))


def idl_request(srv_type: Any, part: str) -> Any:
    """A service's ``Request`` or ``Response`` struct as rmw_cyclonedds sends it: the 16-byte header
    (``uint64 guid``, ``int64 seq``, the member names rmw_cyclonedds's serdata.hpp uses) then the fields."""
    msg_type = getattr(srv_type, part)
    return _struct(msg_type, request_type(srv_type.__msgtype__, part), header=True)
