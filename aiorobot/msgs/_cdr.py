"""ROS 2 CDR (XCDR1, as rmw_fastrtps and rmw_zenoh write it): generated codecs.

Each message type gets one flat serializer and one flat deserializer, generated on
first use. Nested messages are inlined; runs of primitives whose alignment is known
at generation time become a single ``struct`` call. Output is byte-identical to
rosbags' ``serialize_cdr(msg, typename, little_endian=True)``.

Errors never leak as ``struct.error`` or ``IndexError``: each generated line knows
which field it handles, so a failure names the type, the field and the offset.
"""

from __future__ import annotations

import struct
from collections.abc import Callable
from typing import Any

from ._classgen import Message
from ._registry import get
from ._spec import PRIMITIVES

__all__ = ["DeserializationError", "SerializationError", "deserialize", "serialize"]


class Bad(Exception):
    """Raised inside generated codecs; turned into (De)SerializationError with context."""


class DeserializationError(ValueError):
    """Bytes that are not a valid CDR encoding of the requested type."""


class SerializationError(TypeError, ValueError):
    """A message whose field values cannot be encoded (wrong type, range or length)."""


_SER: dict[type, Callable[[Any], bytes]] = {}
_DES: dict[tuple[type, str, bool], Callable[[Any, int], tuple[Any, int]]] = {}
_SER_ERRORS = (struct.error, TypeError, ValueError, AttributeError, OverflowError, Bad)
_DES_ERRORS = (struct.error, ValueError, IndexError, OverflowError, MemoryError, TypeError, Bad)



def serialize(msg: Any) -> bytes:
    """Encode ``msg`` as ROS 2 CDR (little endian), with the 4-byte encapsulation header.

    Raises SerializationError (a TypeError and ValueError) naming the type and field
    when a value has the wrong type, is out of range or breaks a length bound.
    """
    cls = msg.__class__
    fn = _SER.get(cls)
    if fn is None:
        if not isinstance(msg, Message):
            raise TypeError(f"serialize() expects an aiorobot.msgs message instance, got "
                            f"{cls.__name__} {msg!r:.80}")
        from ._cdr_gen import build_serializer  # code generation is loaded on first use

        base = cls._base  # a delivered (read-only) message encodes as its mutable class
        fn = _SER.get(base) or build_serializer(base)
        _SER[cls] = _SER[base] = fn
    try:
        return fn(msg)
    except _SER_ERRORS as exc:
        raise _ser_error(msg, exc) from None


def _ser_error(msg: Any, exc: BaseException) -> SerializationError:
    from ._cdr_gen import fmt_path, where

    entries, local = where(exc.__traceback__)
    detail = str(exc)
    path = ""
    if len(entries) > 1:  # a batched struct call: find the offending value
        for p, typ in entries:
            value = _lookup(msg, fmt_path(p, local))
            problem = _check_primitive(typ, value)
            if problem:
                path, detail = fmt_path(p, local), problem
                break
    if not path and entries:
        path = fmt_path(entries[0][0], local)
        typ = entries[0][1]
        value = _lookup(msg, path)
        problem = _check_primitive(typ, value) if typ in PRIMITIVES else None
        detail = problem or detail
    place = f" field {path!r}" if path else ""
    return SerializationError(f"cannot serialize {msg.__msgtype__}:{place} {detail}")


_MISSING = object()


def _lookup(msg: Any, path: str) -> Any:
    obj = msg
    for part in path.replace(" (length)", "").replace("[", ".[").split("."):
        if not part:
            continue
        try:
            obj = obj[int(part[1:-1])] if part.startswith("[") else getattr(obj, part)
        except (AttributeError, IndexError, ValueError, TypeError):
            return _MISSING
    return obj


def _check_primitive(typ: str, value: Any) -> str | None:
    """Why ``value`` cannot be encoded as ``typ`` (None if it can)."""
    if value is _MISSING or typ not in PRIMITIVES:
        return None
    char = PRIMITIVES[typ][0]
    try:
        struct.pack("<" + char, value)
    except (struct.error, TypeError, OverflowError):
        from ._spec import _INT_RANGES

        if typ in _INT_RANGES and isinstance(value, int):
            lo, hi = _INT_RANGES[typ]
            return f"expects {typ} in [{lo}, {hi}], got {value}"
        return f"expects {typ}, got {type(value).__name__} {value!r:.60}"
    return None


def deserialize(data: bytes | bytearray | memoryview, msg_type: type | str, *, view: bool = False) -> Any:
    """Decode CDR ``data`` (with its 4-byte encapsulation header) as ``msg_type``.

    ``msg_type`` is a message class or a name like ``"geometry_msgs/msg/Twist"``.
    Little- and big-endian CDR are accepted, as are up to 3 trailing padding bytes.
    Raises DeserializationError (a ValueError) naming the type, field and offset.
    ``view=True``: the message in the form subscribers get it: numeric array fields of
    little-endian data are numpy views into ``data`` instead of copies (read-only when ``data`` is
    ``bytes``; ``data`` must then not change while the message is in use), arrays converted from
    big-endian data are read-only too, and sequences of strings and messages are read-only lists.
    """
    cls = msg_type if isinstance(msg_type, type) else get(msg_type)
    if not (isinstance(cls, type) and issubclass(cls, Message)):
        raise TypeError(f"deserialize() expects a message type, got {msg_type!r}; for services "
                        "use .Request or .Response, for actions .Goal, .Result, .Feedback")
    n = len(data)
    if n < 4:
        raise DeserializationError(f"cannot deserialize {cls.__msgtype__}: got {n} bytes, too short "
                                   "for the 4-byte CDR encapsulation header")
    if data[0] != 0 or data[1] not in (0, 1):
        raise DeserializationError(
            f"cannot deserialize {cls.__msgtype__}: unsupported CDR encapsulation header "
            f"{bytes(data[:4]).hex(' ')}; expected 00 01 (CDR little endian) or 00 00 (big endian)")
    endian = "<" if data[1] == 1 else ">"
    fn = _DES.get((cls, endian, view))
    if fn is None:
        from ._cdr_gen import build_deserializer

        fn = _DES[(cls, endian, view)] = build_deserializer(cls, endian, view)
    try:
        obj, end = fn(data, 4)
    except _DES_ERRORS as exc:
        raise _des_error(cls, data, exc) from None
    if n - end > 3:
        raise DeserializationError(
            f"cannot deserialize {cls.__msgtype__}: {n - end} unexpected bytes after the message "
            f"(it ends at byte {end} of {n}; at most 3 padding bytes may follow): wrong type?")
    return obj


def decoder(msg_type: type, *, view: bool = False) -> Callable[[Any], Any]:
    """``deserialize(data, msg_type, view=view)`` as one function for a receiver that decodes many
    messages of one type: little-endian CDR (what every ROS 2 node sends) goes straight to the
    type's generated decoder; anything else (big endian, a bad header, malformed or trailing
    bytes) goes through :func:`deserialize`, which decodes it or raises its DeserializationError."""
    fn = _DES.get((msg_type, "<", view))
    if fn is None:
        from ._cdr_gen import build_deserializer

        fn = _DES[(msg_type, "<", view)] = build_deserializer(msg_type, "<", view)

    def decode(data: Any) -> Any:
        if data[:2] == b"\0\1":
            try:
                obj, end = fn(data, 4)
            except _DES_ERRORS:
                pass  # deserialize says what is wrong
            else:
                if len(data) - end <= 3:
                    return obj
        return deserialize(data, msg_type, view=view)

    return decode


def _des_error(cls: type, data: Any, exc: BaseException) -> DeserializationError:
    from ._cdr_gen import fmt_path, where

    entries, local = where(exc.__traceback__)
    offset = local.get("p")
    if isinstance(exc, Bad):
        detail = str(exc)
    elif isinstance(exc, struct.error) or "smaller than requested" in str(exc):
        detail = f"data ends after {len(data)} bytes (truncated?)"
    else:
        detail = f"{type(exc).__name__}: {exc}"
    place = ""
    if entries:
        fields = ", ".join(repr(fmt_path(p, local)) for p, _ in entries[:4])
        more = ", ..." if len(entries) > 4 else ""
        place = f" reading field {fields}{more}"
        if isinstance(offset, int):
            place += f" at byte {offset}"
    return DeserializationError(f"cannot deserialize {cls.__msgtype__} from {len(data)} bytes:"
                                f"{place}: {detail}")


def _debug_source(msg_type: type | str, kind: str = "ser") -> str:  # pragma: no cover - dev aid
    """The generated source of a codec (for debugging the generator)."""
    from ._cdr_gen import build_deserializer, build_serializer, generated_source

    cls = msg_type if isinstance(msg_type, type) else get(msg_type)
    fn = build_serializer(cls) if kind == "ser" else build_deserializer(cls, "<")
    return generated_source(fn)
