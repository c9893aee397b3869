"""CDR code generation: one flat serializer and deserializer per message type.

Nested messages are inlined; runs of primitives whose alignment is known at
generation time become a single ``struct`` call. Every generated line records the
field it handles, so errors can name the field (see ``where``).
"""

from __future__ import annotations

import struct
from collections.abc import Callable
from types import CodeType, TracebackType
from typing import Any

import numpy as np

from ._cdr import Bad
from ._classgen import FrozenList, as_array, as_fixed_array, dtype_of
from ._registry import get
from ._spec import ARRAY, PRIMITIVES, SCALAR, SEQUENCE, FieldType, MsgSpec

__all__ = ["build_deserializer", "build_parts_serializer", "build_serializer", "fmt_path", "generated_source", "where"]

HEADER_LE = b"\x00\x01\x00\x00"
_PAD = tuple(b"\x00" * i for i in range(8))


def _min_size(t: FieldType) -> int:
    """A lower bound of the encoded size of a value of type ``t`` (for sanity checks)."""
    if t.kind == SEQUENCE:
        return 4
    n = t.count if t.kind == ARRAY else 1
    if t.is_primitive:
        return n * PRIMITIVES[t.base][1]
    if t.is_string:
        return n * 4
    spec = get(t.base)._spec  # type: ignore[attr-defined]
    return n * sum(_min_size(f.type) for f in spec.fields)


class _Gen:
    """Code generator state: emitted lines, alignment knowledge and the pending batch."""

    def __init__(self, endian: str, kind: str) -> None:
        self.endian = endian
        self.kind = kind  # "ser" or "des"
        self.lines: list[str] = []
        self.ctx: dict[int, list[tuple[str, str]]] = {}  # line number -> [(path, type)]
        self.ns: dict[str, Any] = {
            "_Bad": Bad, "_PAD": _PAD, "_frombuffer": np.frombuffer, "_arr": as_array,
            "_farr": as_fixed_array, "_U32": struct.Struct(endian + "I"),
        }
        self.view = False  # deserializer: arrays as views into the input, not copies
        self.indent = 1
        self.counter = 0
        self.mod, self.rem = 8, 0  # position (from the payload start) % mod == rem
        self.fmt = ""
        self.items: list[str] = []
        self.item_ctx: list[tuple[str, str]] = []
        self.dynamic = False  # anything but struct calls was emitted
        self.packs = 0

    # -- helpers ---------------------------------------------------------------
    def name(self, prefix: str) -> str:
        self.counter += 1
        return f"{prefix}{self.counter}"

    def const(self, prefix: str, value: Any) -> str:
        name = self.name(prefix)
        self.ns[name] = value
        return name

    def emit(self, text: str, ctx: list[tuple[str, str]] | None = None) -> None:
        self.lines.append("    " * self.indent + text)
        if ctx:
            self.ctx[len(self.lines) + 1] = ctx  # +1: the "def" line comes first

    def align(self, size: int, ctx: list[tuple[str, str]]) -> None:
        if size == 1:
            return
        if self.mod >= size:
            pad = -self.rem % size
            self.fmt += "x" * pad
            self.rem = (self.rem + pad) % self.mod
            return
        self.flush()
        self.dynamic = True
        if self.kind == "ser":
            self.emit(f"_ap(_PAD[-p & {size - 1}])", ctx)
            self.emit(f"p = (p + {size - 1}) & -{size}")
        else:
            self.emit(f"p += (4 - p) & {size - 1}", ctx)
        self.mod, self.rem = size, 0

    def advance(self, nbytes: int) -> None:
        self.rem = (self.rem + nbytes) % self.mod

    def unknown(self, mod: int = 1) -> None:
        self.mod, self.rem = mod, 0

    def primitive(self, base: str, item: str, path: str) -> None:
        """Add one primitive to the batch: ``item`` is a value expression (ser) or target."""
        char, size, _ = PRIMITIVES[base]
        self.align(size, [(path, base)])
        self.fmt += char
        self.items.append(item)
        self.item_ctx.append((path, base))
        self.advance(size)

    def flush(self) -> None:
        if not self.fmt:
            return
        fmt, items, ctx = self.fmt, self.items, self.item_ctx
        self.fmt, self.items, self.item_ctx = "", [], []
        st = struct.Struct(self.endian + fmt)
        if not items:  # only padding
            self.dynamic = True
            if self.kind == "ser":
                self.emit(f"_ap(_PAD[{st.size}])")
                self.emit(f"p += {st.size}")
            else:
                self.emit(f"p += {st.size}")
            return
        s = self.const("_S", st)
        if self.kind == "ser":
            self.packs += 1
            self.emit(f"_ap({s}.pack({', '.join(items)}))", ctx)
            self.emit(f"p += {st.size}")
        else:
            self.emit(f"{', '.join(items)}, = {s}.unpack_from(d, p)", ctx)
            self.emit(f"p += {st.size}")

    def source(self, header: str, footer: list[str]) -> str:
        return "\n".join([header, *self.lines, *("    " + f for f in footer)]) + "\n"


# ---------------------------------------------------------------- serializer


def _ser_fields(g: _Gen, spec: MsgSpec, expr: str, path: str) -> None:
    if len(spec.fields) > 1 and "." in expr:
        local = g.name("_m")
        g.emit(f"{local} = {expr}", [(path or spec.name, spec.name)])
        expr = local
    for f in spec.fields:
        _ser_value(g, f.type, f"{expr}.{f.name}", f"{path}{f.name}")


def _ser_value(g: _Gen, t: FieldType, expr: str, path: str) -> None:
    ctx = [(path, str(t))]
    if t.kind == SCALAR:
        if t.is_primitive:
            g.primitive(t.base, expr, path)
        elif t.is_string:
            _ser_string(g, t, expr, path)
        else:
            _ser_fields(g, get(t.base)._spec, expr, path + ".")  # type: ignore[attr-defined]
        return
    if t.is_primitive:
        _, size, _ = PRIMITIVES[t.base]
        dt = g.const("_D", dtype_of(t.base))
        arr = g.name("_a")
        if t.kind == ARRAY:
            g.emit(f"{arr} = _farr({expr}, {dt}, {t.count}, {path!r})", ctx)
            g.align(size, ctx)
            g.flush()
            g.dynamic = True
            g.emit(f"_ap({arr}.tobytes())", ctx)
            g.emit(f"p += {size * t.count}")
            g.advance(size * t.count)
            return
        g.emit(f"{arr} = _arr({expr}, {dt})", ctx)
        _check_bound(g, t, arr, path)
        g.primitive("uint32", f"len({arr})", path + " (length)")
        g.flush()
        g.dynamic = True
        if size > 4:
            g.emit(f"if p & 7 and len({arr}):", ctx)
            g.emit("    _ap(_PAD[4])")
            g.emit("    p += 4")
        g.emit(f"_ap({arr}.data)", ctx)
        g.emit(f"p += {arr}.nbytes")
        g.unknown(min(size, 4))
        return
    seq = g.name("_l")
    g.emit(f"{seq} = {expr}", ctx)
    if t.kind == ARRAY:
        g.emit(f"if len({seq}) != {t.count}: raise _Bad('is a fixed array of {t.count} elements, "
               f"got %d' % len({seq}))", ctx)
    else:
        _check_bound(g, t, seq, path)
        g.primitive("uint32", f"len({seq})", path + " (length)")
    g.flush()
    g.dynamic = True
    idx, elem = g.name("_i"), g.name("_e")
    g.emit(f"for {idx}, {elem} in enumerate({seq}):")
    g.indent += 1
    g.unknown()
    _ser_value(g, t.element, elem, f"{path}[{{{idx}}}]")
    g.flush()
    g.indent -= 1
    g.unknown()


def _check_bound(g: _Gen, t: FieldType, name: str, path: str) -> None:
    if t.kind == SEQUENCE and t.count:
        g.emit(f"if len({name}) > {t.count}: raise _Bad('is bounded to {t.count} elements, "
               f"got %d' % len({name}))", [(path, str(t))])


def _ser_string(g: _Gen, t: FieldType, expr: str, path: str) -> None:
    ctx = [(path, str(t))]
    enc = g.name("_s")
    if t.base == "string":
        g.emit(f"{enc} = {expr}.encode()", ctx)
        length = f"len({enc}) + 1"
    else:
        g.emit(f"{enc} = {expr}.encode('utf-16-le')", ctx)
        length = f"len({enc}) // 2"
    if t.string_bound:
        unit = "len({enc})" if t.base == "string" else f"len({enc}) // 2"
        unit = unit.format(enc=enc)
        g.emit(f"if {unit} > {t.string_bound}: raise _Bad('is bounded to {t.string_bound} "
               f"characters, got %d' % {unit})", ctx)
    g.primitive("uint32", length, path)
    g.flush()
    g.dynamic = True
    g.emit(f"_ap({enc})", ctx)
    if t.base == "string":
        g.emit("_ap(_NUL)")
        g.emit(f"p += len({enc}) + 1")
        g.unknown()
    else:
        g.emit(f"p += len({enc})")
        g.unknown(2)


def _ser_gen(spec: MsgSpec) -> _Gen:
    """A serializer's body: the CDR parts appended to ``o``, ``p`` their length after the header."""
    g = _Gen("<", "ser")
    g.emit("o = [_HDR]")
    g.emit("_ap = o.append")
    g.emit("p = 0")
    _ser_fields(g, spec, "m", "")
    g.flush()
    g.ns["_HDR"] = HEADER_LE
    g.ns["_NUL"] = b"\x00"
    return g


def build_serializer(cls: type) -> Callable[[Any], bytes]:
    spec: MsgSpec = cls._spec  # type: ignore[attr-defined]
    g = _ser_gen(spec)
    if not g.dynamic and g.packs == 1:
        # a fixed layout: one struct call, no list needed
        keep: list[str] = []
        ctx: dict[int, list[tuple[str, str]]] = {}
        for lineno, line in enumerate(g.lines[3:], 5):  # line 2 is the first emitted one
            if line.strip().startswith("p +="):
                continue
            keep.append(line.replace("_ap(", "return _HDR + (", 1))
            if lineno in g.ctx:
                ctx[len(keep) + 1] = g.ctx[lineno]
        g.lines, g.ctx = keep, ctx
        src = g.source("def serialize(m):", [])
    else:
        src = g.source("def serialize(m):", ["return b''.join(o)"])
    return _compile(src, g, f"<aiorobot.msgs CDR serializer {spec.name}>", "serialize")


def build_parts_serializer(cls: type) -> Callable[[Any], tuple[list[Any], int]]:
    """The serializer of ``cls`` stopping short of the join: ``(parts, size)``, the CDR as a list
    of buffers (bytes, and memoryviews of the message's arrays) and their total length, for a
    writer that copies them straight into a buffer it was lent (a shared-memory sample), so a
    large array is copied once instead of twice. ``b"".join(parts)`` is ``serialize(m)``."""
    spec: MsgSpec = cls._spec  # type: ignore[attr-defined]
    g = _ser_gen(spec)
    src = g.source("def serialize_parts(m):", [f"return o, p + {len(HEADER_LE)}"])
    return _compile(src, g, f"<aiorobot.msgs CDR parts serializer {spec.name}>", "serialize_parts")


# -------------------------------------------------------------- deserializer


def _des_fields(g: _Gen, spec: MsgSpec, path: str) -> str:
    args = [_des_value(g, f.type, f"{path}{f.name}") for f in spec.fields]
    cls = g.const("_C", get(spec.name))
    return f"{cls}({', '.join(args)})"


def _des_value(g: _Gen, t: FieldType, path: str) -> str:
    ctx = [(path, str(t))]
    if t.kind == SCALAR:
        if t.is_primitive:
            var = g.name("_x")
            g.primitive(t.base, var, path)
            return var
        if t.is_string:
            return _des_string(g, t, path)
        return _des_fields(g, get(t.base)._spec, path + ".")  # type: ignore[attr-defined]
    if t.is_primitive:
        _, size, _ = PRIMITIVES[t.base]
        dt = g.const("_D", dtype_of(t.base).newbyteorder(g.endian))
        var = g.name("_x")
        if g.endian == "<" or size == 1:
            copy = "" if g.view else ".copy()"
        else:  # big endian data: convert to native little-endian arrays
            copy = f".astype({g.const('_D', dtype_of(t.base))})"
        if t.kind == ARRAY:
            g.align(size, ctx)
            g.flush()
            g.dynamic = True
            nbytes = size * t.count
            g.emit(f"if {nbytes} > L - p: raise _Bad('needs {nbytes} bytes, %d left' % (L - p))",
                   ctx)
            g.emit(f"{var} = _frombuffer(d, {dt}, {t.count}, p){copy}", ctx)
            _read_only(g, var, copy)
            g.emit(f"p += {nbytes}")
            g.advance(nbytes)
            return var
        count = g.name("_n")
        g.primitive("uint32", count, path + " (length)")
        g.flush()
        g.dynamic = True
        _des_bound(g, t, count, path)
        if size > 4:
            g.emit(f"if {count}: p += (4 - p) & {size - 1}")
        g.emit(f"if {count} * {size} > L - p: raise _Bad('sequence of %d {t.base} needs %d "
               f"bytes, %d left' % ({count}, {count} * {size}, L - p))", ctx)
        g.emit(f"{var} = _frombuffer(d, {dt}, {count}, p){copy}", ctx)
        _read_only(g, var, copy)
        g.emit(f"p += {count} * {size}")
        g.unknown(min(size, 4))
        return var
    seq = g.name("_l")
    if t.kind == ARRAY:
        count = str(t.count)
        g.flush()
    else:
        count = g.name("_n")
        g.primitive("uint32", count, path + " (length)")
        g.flush()
        _des_bound(g, t, count, path)
        least = _min_size(t.element)
        g.emit(f"if {count} * {least} > L - p: raise _Bad('sequence of %d elements cannot fit "
               f"in the %d bytes left' % ({count}, L - p))", ctx)
    g.dynamic = True
    idx = g.name("_i")
    g.emit(f"{seq} = []")
    g.emit(f"for {idx} in range({count}):")
    g.indent += 1
    g.unknown()
    value = _des_value(g, t.element, f"{path}[{{{idx}}}]")
    g.flush()
    g.emit(f"{seq}.append({value})")
    g.indent -= 1
    g.unknown()
    if g.view:  # the message as subscribers get it: its sequences read-only
        g.ns["_FL"] = FrozenList
        g.emit(f"{seq} = _FL({seq})")
    return seq


def _read_only(g: _Gen, var: str, copy: str) -> None:
    """In view mode an array converted from big-endian data is a new, writable array: make it
    read-only like the views (a message decoded with ``view=True`` is in its delivered form)."""
    if g.view and copy.startswith(".astype"):
        g.emit(f"{var}.flags.writeable = False")


def _des_bound(g: _Gen, t: FieldType, count: str, path: str) -> None:
    if t.kind == SEQUENCE and t.count:
        g.emit(f"if {count} > {t.count}: raise _Bad('is bounded to {t.count} elements, got %d' "
               f"% {count})", [(path, str(t))])


def _des_string(g: _Gen, t: FieldType, path: str) -> str:
    ctx = [(path, str(t))]
    count, var = g.name("_n"), g.name("_x")
    g.primitive("uint32", count, path + " (length)")
    g.flush()
    g.dynamic = True
    if t.base == "string":
        g.emit(f"if {count} > L - p: raise _Bad('string length %d exceeds the %d bytes left' "
               f"% ({count}, L - p))", ctx)
        g.emit(f"if {count} and d[p + {count} - 1]: raise _Bad('string is not NUL-terminated')",
               ctx)
        g.emit(f"{var} = str(d[p:p + {count} - 1], 'utf-8') if {count} > 1 else ''", ctx)
        g.emit(f"p += {count}")
        g.unknown()
    else:
        enc = "utf-16-le" if g.endian == "<" else "utf-16-be"
        g.emit(f"if 2 * {count} > L - p: raise _Bad('wstring of %d characters exceeds the %d "
               f"bytes left' % ({count}, L - p))", ctx)
        g.emit(f"{var} = str(d[p:p + 2 * {count}], {enc!r})", ctx)
        g.emit(f"p += 2 * {count}")
        g.unknown(2)
    if t.string_bound:
        g.emit(f"if len({var}) > {t.string_bound}: raise _Bad('is bounded to {t.string_bound} "
               f"characters, got %d' % len({var}))", ctx)
    return var


def build_deserializer(cls: type, endian: str, view: bool = False) -> Callable[[Any, int], tuple[Any, int]]:
    spec: MsgSpec = cls._spec  # type: ignore[attr-defined]
    g = _Gen(endian, "des")
    g.view = view
    g.emit("L = len(d)")
    value = _des_fields(g, spec, "")
    g.flush()
    src = g.source("def deserialize(d, p):", [f"return {value}, p"])
    return _compile(src, g, f"<aiorobot.msgs CDR deserializer {spec.name}>", "deserialize")


def _compile(src: str, g: _Gen, filename: str, fname: str) -> Any:
    code = compile(src, filename, "exec")
    exec(code, g.ns)  # noqa: S102 - generated from a validated spec
    fn = g.ns[fname]
    # keyed by id: equal code objects (e.g. Twist's and Wrench's codecs) compare equal
    _CONTEXT[id(fn.__code__)] = (fn.__code__, g.ctx)
    _SOURCES[id(fn.__code__)] = src
    return fn


_CONTEXT: dict[int, tuple[CodeType, dict[int, list[tuple[str, str]]]]] = {}
_SOURCES: dict[int, str] = {}


def where(tb: TracebackType | None) -> tuple[list[tuple[str, str]], dict[str, Any]]:
    """The (path, type) entries and locals of the generated line that failed."""
    while tb is not None:
        entry = _CONTEXT.get(id(tb.tb_frame.f_code))
        if entry is not None and entry[0] is tb.tb_frame.f_code:
            return entry[1].get(tb.tb_lineno, []), dict(tb.tb_frame.f_locals)
        tb = tb.tb_next
    return [], {}


def fmt_path(path: str, local: dict[str, Any]) -> str:
    try:
        return path.format(**local)
    except (KeyError, IndexError, ValueError):
        return path




def generated_source(fn: Callable[..., Any]) -> str:
    """The source of a generated codec (for debugging the generator)."""
    return _SOURCES[id(fn.__code__)]
