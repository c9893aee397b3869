"""Interface specifications: field types, message specs and the .msg/.srv/.action parser.

A message spec is plain data (name, constants, fields) from which classes, CDR codecs,
type hashes and definition texts are generated. Field types are written as in .msg
files, fully qualified: ``float64``, ``string<=10``, ``uint8[]``, ``float64[9]``,
``int32[<=5]``, ``geometry_msgs/msg/Point[]``.
"""

from __future__ import annotations

import keyword
import re
from typing import Any, NamedTuple

__all__ = [
    "PRIMITIVES",
    "Constant",
    "Field",
    "FieldType",
    "MsgSpec",
    "parse_action",
    "parse_msg",
    "parse_srv",
    "parse_type",
]

# primitive -> (struct format char, size in bytes, numpy dtype string)
PRIMITIVES: dict[str, tuple[str, int, str]] = {
    "bool": ("?", 1, "?"),
    "byte": ("B", 1, "u1"),
    "char": ("B", 1, "u1"),
    "int8": ("b", 1, "i1"),
    "uint8": ("B", 1, "u1"),
    "int16": ("h", 2, "<i2"),
    "uint16": ("H", 2, "<u2"),
    "int32": ("i", 4, "<i4"),
    "uint32": ("I", 4, "<u4"),
    "int64": ("q", 8, "<i8"),
    "uint64": ("Q", 8, "<u8"),
    "float32": ("f", 4, "<f4"),
    "float64": ("d", 8, "<f8"),
}
_INT_RANGES: dict[str, tuple[int, int]] = {
    "byte": (0, 255),
    "char": (0, 255),
    "int8": (-(2**7), 2**7 - 1),
    "uint8": (0, 2**8 - 1),
    "int16": (-(2**15), 2**15 - 1),
    "uint16": (0, 2**16 - 1),
    "int32": (-(2**31), 2**31 - 1),
    "uint32": (0, 2**32 - 1),
    "int64": (-(2**63), 2**63 - 1),
    "uint64": (0, 2**64 - 1),
}
SCALAR, ARRAY, SEQUENCE = 0, 1, 2

_TYPE_RE = re.compile(
    r"^(?P<base>[A-Za-z][A-Za-z0-9_]*(?:/[A-Za-z][A-Za-z0-9_]*){0,2})"
    r"(?:<=(?P<sbound>\d+))?"
    r"(?:\[(?P<arr>(?:<=)?\d*)\])?$"
)
_FIELD_NAME_RE = re.compile(r"^[a-z][a-z0-9_]*$")
_CONST_NAME_RE = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")


class FieldType(NamedTuple):
    """The type of one field.

    ``base`` is a primitive name, ``string``, ``wstring`` or a message type
    ``pkg/msg/Name``; ``kind`` is SCALAR, ARRAY (fixed ``count``) or SEQUENCE
    (``count`` is the bound, 0 when unbounded); ``string_bound`` 0 = unbounded.
    """

    base: str
    kind: int = SCALAR
    count: int = 0
    string_bound: int = 0

    @property
    def is_primitive(self) -> bool:
        return self.base in PRIMITIVES

    @property
    def is_string(self) -> bool:
        return self.base in ("string", "wstring")

    @property
    def is_message(self) -> bool:
        return "/" in self.base

    @property
    def element(self) -> FieldType:
        """The element type of an array or sequence (self for scalars)."""
        return FieldType(self.base, SCALAR, 0, self.string_bound)

    def __str__(self) -> str:
        base = f"{self.base}<={self.string_bound}" if self.string_bound else self.base
        if self.kind == ARRAY:
            return f"{base}[{self.count}]"
        if self.kind == SEQUENCE:
            return f"{base}[<={self.count}]" if self.count else f"{base}[]"
        return base


class Field(NamedTuple):
    name: str
    type: FieldType
    default: Any = None  # None: the type's zero value


class Constant(NamedTuple):
    name: str
    type: str
    value: Any


class MsgSpec(NamedTuple):
    """A message type: ``name`` like ``geometry_msgs/msg/Twist``."""

    name: str
    fields: tuple[Field, ...]
    constants: tuple[Constant, ...] = ()

    @property
    def package(self) -> str:
        return self.name.split("/", 1)[0]

    @property
    def short_name(self) -> str:
        return self.name.rsplit("/", 1)[1]

    def dependencies(self) -> list[str]:
        """Message types used by the fields, in field order, without duplicates."""
        return list(dict.fromkeys(f.type.base for f in self.fields if f.type.is_message))


def parse_type(text: str, package: str = "", *, context: str = "") -> FieldType:
    """Parse a .msg type like ``string<=5[<=3]`` or ``Point[]`` into a FieldType.

    Short message names resolve within ``package``; ``Header`` means std_msgs/msg/Header.
    """
    m = _TYPE_RE.match(text)
    if m is None:
        raise ValueError(f"{context}invalid field type {text!r}; expected e.g. 'float64', "
                         "'string<=10', 'uint8[]', 'float64[9]', 'int32[<=5]' or 'pkg/msg/Type'")
    base, sbound, arr = m.group("base"), m.group("sbound"), m.group("arr")
    if base in PRIMITIVES or base in ("string", "wstring"):
        pass
    elif base == "Header":
        base = "std_msgs/msg/Header"
    elif base in ("time", "duration"):
        base = f"builtin_interfaces/msg/{base.capitalize()}"
    else:
        parts = base.split("/")
        if len(parts) == 1:
            if not package:
                raise ValueError(f"{context}type {text!r} needs a package: write 'pkg/{base}'")
            base = f"{package}/msg/{base}"
        elif len(parts) == 2:
            base = f"{parts[0]}/msg/{parts[1]}"
        elif parts[1] not in ("msg", "srv", "action"):
            raise ValueError(f"{context}invalid type {text!r}; expected 'pkg/msg/Type'")
    if sbound is not None and base not in ("string", "wstring"):
        raise ValueError(f"{context}only strings take a bound ('<=N'), got {text!r}")
    string_bound = int(sbound) if sbound else 0
    if arr is None:
        return FieldType(base, SCALAR, 0, string_bound)
    if arr == "":
        return FieldType(base, SEQUENCE, 0, string_bound)
    if arr.startswith("<="):
        return FieldType(base, SEQUENCE, int(arr[2:]), string_bound)
    if int(arr) == 0:
        raise ValueError(f"{context}fixed arrays need a length > 0, got {text!r}")
    return FieldType(base, ARRAY, int(arr), string_bound)


def _strip_comment(line: str) -> str:
    quote = ""
    for i, ch in enumerate(line):
        if quote:
            if ch == quote:
                quote = ""
        elif ch in "\"'":
            quote = ch
        elif ch == "#":
            return line[:i]
    return line


def _unquote(text: str) -> str:
    text = text.strip()
    if len(text) >= 2 and text[0] == text[-1] and text[0] in "\"'":
        inner = text[1:-1]
        if "\\" in inner:  # decode escapes, keeping non-ASCII characters intact
            inner = inner.encode("latin-1", "backslashreplace").decode("unicode_escape")
        return inner
    return text


def _scalar_value(base: str, text: str, context: str) -> Any:
    text = text.strip()
    try:
        if base == "bool":
            low = text.lower()
            if low in ("true", "1"):
                return True
            if low in ("false", "0"):
                return False
            raise ValueError(text)
        if base in ("float32", "float64"):
            return float(text)
        if base in ("string", "wstring"):
            return _unquote(text)
        value = int(text, 0)
    except ValueError:
        raise ValueError(f"{context}value {text!r} is not a valid {base}") from None
    lo, hi = _INT_RANGES[base]
    if not lo <= value <= hi:
        raise ValueError(f"{context}value {value} is out of range for {base} [{lo}, {hi}]")
    return value


def _default_value(ftype: FieldType, text: str, context: str) -> Any:
    if ftype.is_message:
        raise ValueError(f"{context}message fields cannot have a default value")
    if ftype.kind == SCALAR:
        return _scalar_value(ftype.base, text, context)
    text = text.strip()
    if not (text.startswith("[") and text.endswith("]")):
        raise ValueError(f"{context}array default must look like [1, 2, 3], got {text!r}")
    inner = text[1:-1].strip()
    items = [s for s in re.findall(r"\"[^\"]*\"|'[^']*'|[^,]+", inner) if s.strip()] if inner else []
    values = [_scalar_value(ftype.base, s, context) for s in items]
    if ftype.kind == ARRAY and len(values) != ftype.count:
        raise ValueError(f"{context}default has {len(values)} elements, type needs {ftype.count}")
    return tuple(values)


def parse_msg(text: str, name: str) -> MsgSpec:
    """Parse .msg text for message type ``name`` (``pkg/msg/Name``) into a MsgSpec.

    An empty message gets ROS 2's ``uint8 structure_needs_at_least_one_member``.
    """
    package = name.split("/", 1)[0]
    fields: list[Field] = []
    constants: list[Constant] = []
    for lineno, raw in enumerate(text.splitlines(), 1):
        context = f"{name} line {lineno}: "
        stripped = raw.strip()
        if not stripped or stripped.startswith("#"):
            continue
        typ_text, rest = (stripped.split(None, 1) + [""])[:2]
        rest = rest.strip()
        # a constant: TYPE NAME=VALUE (string constants keep '#' in their value)
        if "=" in rest and len(rest.split("=", 1)[0].split()) == 1 and "#" not in rest.split(
                "=", 1)[0]:
            cname, _, value_text = rest.partition("=")
            cname = cname.strip()
            if typ_text not in ("string", "wstring"):
                value_text = _strip_comment(value_text)
            if typ_text not in PRIMITIVES and typ_text not in ("string", "wstring"):
                raise ValueError(f"{context}constants must be primitives or strings, got {typ_text!r}")
            if not _CONST_NAME_RE.match(cname):
                raise ValueError(f"{context}invalid constant name {cname!r}")
            constants.append(Constant(cname, typ_text, _scalar_value(typ_text, value_text, context)))
            continue
        line = _strip_comment(stripped).strip()
        typ_text, fname, default_text = ([*line.split(None, 2), "", ""])[:3]
        if not fname:
            raise ValueError(f"{context}expected 'type name', got {raw.strip()!r}")
        if not _FIELD_NAME_RE.match(fname) or keyword.iskeyword(fname):
            raise ValueError(f"{context}invalid field name {fname!r}; use lowercase letters, digits "
                             "and underscores, starting with a letter (not a Python keyword)")
        if any(f.name == fname for f in fields):
            raise ValueError(f"{context}duplicate field name {fname!r}")
        ftype = parse_type(typ_text, package, context=context)
        default = _default_value(ftype, default_text, context) if default_text.strip() else None
        fields.append(Field(fname, ftype, default))
    if not fields:
        fields.append(Field("structure_needs_at_least_one_member", FieldType("uint8")))
    return MsgSpec(name, tuple(fields), tuple(constants))


def _split_sections(text: str, count: int, name: str) -> list[str]:
    sections: list[list[str]] = [[]]
    for line in text.splitlines():
        if line.strip() == "---":
            sections.append([])
        else:
            sections[-1].append(line)
    if len(sections) != count:
        raise ValueError(f"{name}: expected {count} sections separated by '---' lines, "
                         f"got {len(sections)}")
    return ["\n".join(s) for s in sections]


def parse_srv(text: str, name: str) -> tuple[MsgSpec, MsgSpec]:
    """Parse .srv text for ``pkg/srv/Name``: (Request spec, Response spec)."""
    req, resp = _split_sections(text, 2, name)
    return parse_msg(req, f"{name}_Request"), parse_msg(resp, f"{name}_Response")


def parse_action(text: str, name: str) -> tuple[MsgSpec, MsgSpec, MsgSpec]:
    """Parse .action text for ``pkg/action/Name``: (Goal, Result, Feedback) specs."""
    goal, result, feedback = _split_sections(text, 3, name)
    return (parse_msg(goal, f"{name}_Goal"), parse_msg(result, f"{name}_Result"),
            parse_msg(feedback, f"{name}_Feedback"))


def spec_from_snapshot(name: str, entry: tuple[tuple[Any, ...], tuple[Any, ...]]) -> MsgSpec:
    """Build a MsgSpec from a ``_jazzy.DEFS`` entry."""
    consts, fields = entry
    package = name.split("/", 1)[0]
    return MsgSpec(
        name,
        tuple(Field(f[0], parse_type(f[1], package), f[2] if len(f) > 2 else None) for f in fields),
        tuple(Constant(*c) for c in consts),
    )
