"""Message, service and action classes, generated per type from its spec.

Each message class is built from generated source (``exec``), so construction,
comparison and ``repr`` run straight-line code: a ``Twist()`` costs about a
microsecond. Numeric arrays are numpy arrays; mutable defaults are made fresh
for every instance.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, ClassVar

import numpy as np

from ._spec import _INT_RANGES, ARRAY, PRIMITIVES, SCALAR, FieldType, MsgSpec

__all__ = ["Action", "FrozenList", "Message", "ReadOnlyMessageError", "Service", "build_class",
           "disable_assignment_checks", "enable_assignment_checks", "freezer"]

_ndarray = np.ndarray


class Message:
    """Base class of every generated message class.

    Constructor arguments are checked as rclpy's generated classes check them: type, integer
    and float32 range, string bounds, item types of sequences; a bad one raises TypeError or
    ValueError naming the field. Assignments after construction are checked the same way
    while a ``Runtime(debug_messages=True)`` runs, and cost nothing otherwise.

    rclpy difference: float fields accept ints and numpy numbers (stored as float); rclpy
    accepts only float. Assignment is checked only under ``debug_messages`` (rclpy checks
    every assignment).
    """

    __slots__ = ()
    __msgtype__: ClassVar[str] = ""
    _field_types: ClassVar[dict[str, str]] = {}
    _base: ClassVar[type[Message]]  # the generated class itself; read-only twins inherit it
    _frozen: ClassVar[bool] = False  # True on the read-only twins that subscribers receive

    @classmethod
    def get_fields_and_field_types(cls) -> dict[str, str]:
        """Field names and their .msg types, in definition order (as rclpy)."""
        return dict(cls._field_types)

    def __reduce__(self) -> tuple[Any, ...]:
        from ._registry import rebuild

        return rebuild, (self.__msgtype__, tuple(getattr(self, n) for n in self._base.__slots__))

    def copy(self) -> Any:
        """A deep, mutable copy (numpy arrays copied): what to change instead of a received message."""
        import copy

        return copy.deepcopy(self)

    __hash__ = None  # type: ignore[assignment]  # mutable, compared by value


#: Arrays of at least this many bytes are shared (made read-only) at publish; smaller ones are copied.
SHARE_BYTES = 4096


class ReadOnlyMessageError(AttributeError):
    """Raised on an attempt to change a message as delivered to subscribers."""


class FrozenList(list):  # type: ignore[type-arg]
    """A list that refuses changes: the sequence fields of a delivered message."""

    __slots__ = ()

    def _refuse(self, *_args: Any, **_kwargs: Any) -> Any:
        raise ReadOnlyMessageError("this list belongs to a published message; copy it with list(...) "
                                   "or copy the message with .copy()")

    append = extend = insert = remove = pop = clear = sort = reverse = _refuse
    __setitem__ = __delitem__ = __iadd__ = __imul__ = _refuse

    def __reduce__(self) -> tuple[Any, ...]:
        return list, (list(self),)

    def __copy__(self) -> list[Any]:
        return list(self)

    def __deepcopy__(self, memo: dict[int, Any]) -> list[Any]:
        import copy

        return [copy.deepcopy(x, memo) for x in self]


def _readonly_array(a: np.ndarray, dtype: np.dtype[Any] | None = None) -> np.ndarray:
    """What a subscriber gets for an array field: large ones shared, small ones copied; both read-only.

    A list assigned to the field (rclpy code does ``msg.sequence = [0, 1]``) is copied into an array
    of the field's ``dtype``.
    """
    if not isinstance(a, np.ndarray):
        b = np.array(a) if dtype is None else as_array(a, dtype)
        b.flags.writeable = False
        return b
    if not a.flags.writeable:
        return a
    if a.nbytes >= SHARE_BYTES:
        a.flags.writeable = False  # the publisher's array too: a write after publish raises
        return a
    b = a.copy()
    b.flags.writeable = False
    return b


class _Freezer(dict):  # type: ignore[type-arg]
    """Message class -> its read-only twin for one topic (created on first use)."""

    def __init__(self, topic: str) -> None:
        super().__init__()
        self.topic = topic

    def __missing__(self, cls: type) -> type:
        twin = self[cls] = _frozen_twin(cls, self.topic)
        return twin


_FREEZERS: dict[str, _Freezer] = {}


def freezer(topic: str) -> _Freezer:
    """The shared class table of read-only twins for messages published on ``topic``."""
    f = _FREEZERS.get(topic)
    if f is None:
        f = _FREEZERS[topic] = _Freezer(topic)
    return f


def _frozen_twin(cls: type, topic: str) -> type:
    short = cls.__name__
    text = (f"this {short} was published on {topic}; publish a new one or .copy() it "
            "(subscribers share what was published)")

    def __setattr__(self: Any, name: str, value: Any) -> None:
        raise ReadOnlyMessageError(text)

    def __delattr__(self: Any, name: str) -> None:
        raise ReadOnlyMessageError(text)

    def __new__(twin: type, *args: Any, **kwargs: Any) -> Any:
        return cls(*args, **kwargs)  # type(received)(...) builds a mutable message

    twin = type(cls)(short, (cls,), {"__slots__": (), "__setattr__": __setattr__,
                                      "__delattr__": __delattr__, "__new__": __new__,
                                      "_frozen": True, "__module__": cls.__module__})
    twin.__qualname__ = cls.__qualname__
    return twin


class _InterfaceMeta(type):
    def __repr__(cls) -> str:
        return f"<{cls.__mro__[1].__name__.lower()} type {cls.__msgtype__}>"  # type: ignore[attr-defined]


class Service(metaclass=_InterfaceMeta):
    """Base class of service types: ``Request``, ``Response`` and ``Event`` message classes."""

    __msgtype__: ClassVar[str] = ""
    Request: ClassVar[type[Message]]
    Response: ClassVar[type[Message]]
    Event: ClassVar[type[Message]]

    def __init__(self) -> None:
        name = type(self).__name__
        raise TypeError(f"{type(self).__msgtype__} is a service type, not a message: construct "
                        f"{name}.Request() or {name}.Response() instead")


class Action(metaclass=_InterfaceMeta):
    """Base class of action types.

    ``Goal``, ``Result``, ``Feedback`` and what a transport needs: the ``SendGoal`` and
    ``GetResult`` services and ``FeedbackMessage``, structured as in ROS 2.
    """

    __msgtype__: ClassVar[str] = ""
    Goal: ClassVar[type[Message]]
    Result: ClassVar[type[Message]]
    Feedback: ClassVar[type[Message]]
    SendGoal: ClassVar[type[Service]]
    GetResult: ClassVar[type[Service]]
    FeedbackMessage: ClassVar[type[Message]]

    def __init__(self) -> None:
        name = type(self).__name__
        raise TypeError(f"{type(self).__msgtype__} is an action type, not a message: construct "
                        f"{name}.Goal(), {name}.Result() or {name}.Feedback() instead")


_DTYPES: dict[str, np.dtype[Any]] = {k: np.dtype(v[2]) for k, v in PRIMITIVES.items()}
_EMPTY: dict[str, np.ndarray] = {}


def dtype_of(base: str) -> np.dtype[Any]:
    return _DTYPES[base]


def as_array(value: Any, dtype: np.dtype[Any]) -> np.ndarray:
    """``value`` as a 1-D C-contiguous array of ``dtype`` (no copy when it already is one)."""
    if value.__class__ is _ndarray and value.dtype == dtype and value.ndim == 1 and (
            value.flags.c_contiguous):
        return value
    if isinstance(value, (bytes, bytearray, memoryview)) and dtype.itemsize == 1:
        return np.frombuffer(value, dtype).copy()
    if dtype.itemsize == 1 and isinstance(value, (list, tuple)) and value and isinstance(value[0], bytes):
        return _from_byte_list(value, dtype)
    return np.ascontiguousarray(value, dtype).reshape(-1)


def _from_byte_list(value: list[Any] | tuple[Any, ...], dtype: np.dtype[Any]) -> np.ndarray:
    """rclpy's ``byte[]`` form, a list of one-byte ``bytes`` (``[b'J', b'P']``), as an array."""
    for i, b in enumerate(value):
        if not isinstance(b, bytes) or len(b) != 1:
            raise TypeError(f"item {i}: expected one-byte bytes (as the items before it), found {_got(b)}")
    return np.frombuffer(b"".join(value), dtype).copy()


def as_fixed_array(value: Any, dtype: np.dtype[Any], count: int, where: str) -> np.ndarray:
    arr = as_array(value, dtype)
    if arr.shape[0] != count:
        raise ValueError(f"{where} is a fixed array of {count} elements, got {arr.shape[0]}")
    return arr


_F32_MAX = 3.4028234663852886e38


def _got(value: Any) -> str:
    return f"{type(value).__name__} {value!r:.60}"


def check_float(value: Any, where: str, base: str) -> float:
    """A float field's value: floats, ints and numpy numbers (as float); else TypeError."""
    if isinstance(value, (float, int, np.floating, np.integer)) and not isinstance(value, (bool, np.bool_)):
        value = float(value)
    else:
        raise TypeError(f"{where} expects a float ({base}), got {_got(value)}")
    if base == "float32" and abs(value) > _F32_MAX and value == value and abs(value) != float("inf"):
        raise ValueError(f"{where}: {value!r} is out of range for float32")
    return value


def check_int(value: Any, where: str, base: str) -> int:
    """An integer field's value: ints (and bools, numpy integers) in the type's range."""
    if isinstance(value, (int, np.integer)):
        value = int(value)
    else:
        raise TypeError(f"{where} expects an int ({base}), got {_got(value)}")
    lo, hi = _INT_RANGES[base]
    if not lo <= value <= hi:
        raise ValueError(f"{where}: {value} is out of range for {base} [{lo}, {hi}]")
    return value


def check_bool(value: Any, where: str) -> bool:
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    raise TypeError(f"{where} expects a bool, got {_got(value)}")


def check_str(value: Any, where: str, bound: int) -> str:
    if not isinstance(value, str):
        raise TypeError(f"{where} expects a str, got {_got(value)}")
    if bound and len(value) > bound:
        raise ValueError(f"{where} is bounded to {bound} characters, got {len(value)}")
    return str(value)


def check_message(value: Any, cls: type, where: str) -> Any:
    if not isinstance(value, cls):
        raise TypeError(f"{where} expects a {cls.__msgtype__} message, got {_got(value)}")  # type: ignore[attr-defined]
    return value


def check_list(value: Any, item: Any, where: str, what: str) -> list[Any]:
    """A sequence field of strings or messages: a list (or tuple) whose items are ``item``."""
    if isinstance(value, (str, bytes)) or not hasattr(value, "__iter__"):
        raise TypeError(f"{where} expects a list of {what}, got {_got(value)}")
    value = value if isinstance(value, list) else list(value)
    for i, x in enumerate(value):
        if not isinstance(x, item):
            raise TypeError(f"{where}[{i}] expects a {what}, got {_got(x)}")
    return value  # type: ignore[no-any-return]


def checked_array(value: Any, dtype: np.dtype[Any], where: str) -> np.ndarray:
    try:
        return as_array(value, dtype)
    except (TypeError, ValueError, OverflowError) as exc:
        raise (TypeError if isinstance(exc, TypeError) else ValueError)(
            f"{where} expects a sequence of {dtype.name}: {exc}") from None


def checked_fixed_array(value: Any, dtype: np.dtype[Any], count: int, where: str) -> np.ndarray:
    arr = checked_array(value, dtype, where)
    if arr.shape[0] != count:
        raise ValueError(f"{where} is a fixed array of {count} elements, got {arr.shape[0]}")
    return arr


def _zero_literal(base: str) -> str:
    if base == "bool":
        return "False"
    if base in ("float32", "float64"):
        return "0.0"
    if base in ("string", "wstring"):
        return "''"
    return "0"


def _class_source(spec: MsgSpec, ns: dict[str, Any], get: Callable[[str], type]) -> str:
    names = [f.name for f in spec.fields]
    params: list[str] = []
    checks: list[str] = []  # skipped when _t (a copy made by _cp from a checked message)
    body: list[str] = []
    eq: list[str] = []
    for i, f in enumerate(spec.fields):
        t: FieldType = f.type
        n = f.name
        where = f"{spec.name}.{n}"
        if t.kind == SCALAR and not t.is_message:
            default = repr(f.default) if f.default is not None else _zero_literal(t.base)
            params.append(f"{n}={default}")
            if t.base in ("float32", "float64"):
                lim = "" if t.base == "float64" else f" or not -{_F32_MAX!r} <= {n} <= {_F32_MAX!r}"
                checks.append(f"if {n}.__class__ is not float{lim}: {n} = _chf({n}, {where!r}, {t.base!r})")
            elif t.base == "bool":
                checks.append(f"if {n}.__class__ is not bool: {n} = _chb({n}, {where!r})")
            elif t.is_string:
                lim = f" or len({n}) > {t.string_bound}" if t.string_bound else ""
                checks.append(f"if {n}.__class__ is not str{lim}: {n} = _chs({n}, {where!r}, {t.string_bound})")
            else:
                lo, hi = _INT_RANGES[t.base]
                checks.append(f"if {n}.__class__ is not int or not {lo} <= {n} <= {hi}: "
                              f"{n} = _chi({n}, {where!r}, {t.base!r})")
            body.append(f"self.{n} = {n}")
            eq.append(f"self.{n} == other.{n}")
            continue
        params.append(f"{n}=None")
        if t.kind == SCALAR:  # nested message
            ns[f"_T{i}"] = get(t.base)
            checks.append(f"if {n} is not None and not isinstance({n}, _T{i}): _chm({n}, _T{i}, {where!r})")
            body.append(f"self.{n} = _T{i}() if {n} is None else {n}")
            eq.append(f"self.{n} == other.{n}")
        elif t.is_primitive:
            ns[f"_D{i}"] = _DTYPES[t.base]
            if f.default is not None:
                ns[f"_V{i}"] = np.array(f.default, _DTYPES[t.base])
                fresh = f"_V{i}.copy()"
            elif t.kind == ARRAY:
                fresh = f"_zeros({t.count}, _D{i})"
            else:
                fresh = f"_empty(0, _D{i})"
            if t.kind == ARRAY:
                conv = f"_farr({n}, _D{i}, {t.count}, {where!r}) if _t else _cfarr({n}, _D{i}, {t.count}, {where!r})"
            else:
                conv = f"_arr({n}, _D{i}) if _t else _carr({n}, _D{i}, {where!r})"
            body.append(f"self.{n} = {fresh} if {n} is None else {conv}")
            eq.append(f"_aeq(self.{n}, other.{n})")
        elif t.is_string:
            if f.default is not None:
                fresh = repr(list(f.default))
            elif t.kind == ARRAY:
                fresh = f"[''] * {t.count}"
            else:
                fresh = "[]"
            checks.append(f"if {n} is not None: {n} = _chl({n}, str, {where!r}, 'str')")
            body.append(f"self.{n} = {fresh} if {n} is None else {n}")
            eq.append(f"self.{n} == other.{n}")
        else:  # arrays and sequences of messages
            ns[f"_T{i}"] = get(t.base)
            fresh = f"[_T{i}() for _ in range({t.count})]" if t.kind == ARRAY else "[]"
            checks.append(f"if {n} is not None: {n} = _chl({n}, _T{i}, {where!r}, {t.base!r})")
            body.append(f"self.{n} = {fresh} if {n} is None else {n}")
            eq.append(f"self.{n} == other.{n}")
    freeze = ["def _fz(m, F):", "    if m._frozen:", "        return m", "    c = _new(F[_Self])"]
    for i, f in enumerate(spec.fields):
        t = f.type
        n = f.name
        if t.kind == SCALAR and not t.is_message:
            freeze.append(f"    _S{i}(c, m.{n})")
        elif t.kind == SCALAR:
            freeze.append(f"    _S{i}(c, _T{i}._fz(m.{n}, F))")
        elif t.is_primitive:
            ns[f"_D{i}"] = _DTYPES[t.base]
            freeze.append(f"    _S{i}(c, _ro(m.{n}, _D{i}))")
        elif t.is_string:
            freeze.append(f"    _S{i}(c, _FL(m.{n}))")
        else:
            freeze.append(f"    _S{i}(c, _FL([x._fz(x, F) for x in m.{n}]))")
    freeze.append("    return c")
    binds: list[str] = []
    expr = _copy_expr(spec, "_Self", "m", ns, get, binds)
    freeze += ["def _cp(m, F=None):", *(f"    {b}" for b in binds), f"    return {expr}"]
    dotted = spec.name.replace("/", ".")
    reprs = ", ".join(f"{n}={{self.{n}!r}}" for n in names)
    lines = [
        f"class {spec.short_name}(_Message):",
        f"    __slots__ = {tuple(names)!r}",
        f"    __match_args__ = {tuple(names)!r}",
        f"    __msgtype__ = {spec.name!r}",
    ]
    lines += [f"    {c.name} = {c.value!r}" for c in spec.constants]
    lines += [
        f"    def __init__(self, {', '.join([*params, '_t=False'])}):",
        *(["        if not _t:"] + [f"            {c}" for c in checks] if checks else []),
        *(f"        {b}" for b in body),
        "    def __eq__(self, other):",
        "        if getattr(other.__class__, '_base', None) is not self._base:",
        "            return NotImplemented",
        f"        return bool({' and '.join(eq)})",
        "    def __repr__(self):",
        f"        return f'{dotted}({reprs})'",
    ]
    return "\n".join(lines) + "\n", "\n".join(freeze) + "\n"


def _copy_expr(spec: MsgSpec, cls_name: str, src: str, ns: dict[str, Any],
               get: Callable[[str], type], binds: list[str]) -> str:
    """One expression building a copy of ``src``, nested messages inlined (their sources bound
    to locals in ``binds``): scalars shared, arrays through ``_ro``, sequences as FrozenList."""
    args = []
    for f in spec.fields:
        t = f.type
        ref = f"{src}.{f.name}"
        if t.kind == SCALAR and not t.is_message:
            args.append(ref)
        elif t.kind == SCALAR:
            k = len(binds) + 1
            nested = get(t.base)
            ns[f"_C{k}"] = nested
            binds.append(f"_v{k} = {ref}")
            args.append(_copy_expr(nested._spec, f"_C{k}", f"_v{k}", ns, get, binds))  # type: ignore[attr-defined]
        elif t.is_primitive:
            dtype_name = f"_D_{t.base}"
            ns[dtype_name] = _DTYPES[t.base]
            args.append(f"_ro({ref}, {dtype_name})")
        elif t.is_string:
            args.append(f"_FL({ref})")
        else:
            args.append(f"_FL([x._cp(x) for x in {ref}])")
    return f"{cls_name}({', '.join([*args, 'True'])})"


#: Every generated message class, for switching assignment checks on and off.
_CLASSES: list[type] = []
#: How many users (runtimes with ``debug_messages``) want assignment checks now.
_CHECK_USERS = 0


def enable_assignment_checks() -> None:
    """Check every assignment to a message field as the constructor checks its argument
    (``msg.data = 'five'`` on an Int32 raises TypeError naming the field), in every message
    class, until as many :func:`disable_assignment_checks` calls. Process-wide: message
    classes are shared."""
    global _CHECK_USERS
    _CHECK_USERS += 1
    if _CHECK_USERS == 1:
        for cls in _CLASSES:
            _install_checks(cls)


def disable_assignment_checks() -> None:
    """Undo one :func:`enable_assignment_checks`; the last one restores unchecked (free) assignment."""
    global _CHECK_USERS
    if _CHECK_USERS == 0:
        return
    _CHECK_USERS -= 1
    if _CHECK_USERS == 0:
        for cls in _CLASSES:
            if "__setattr__" in cls.__dict__:
                del cls.__setattr__  # type: ignore[misc]


def _field_checker(spec: MsgSpec, i: int, field_classes: dict[int, type]) -> Callable[[Any], Any]:
    f = spec.fields[i]
    t: FieldType = f.type
    where = f"{spec.name}.{f.name}"
    if t.kind == SCALAR and not t.is_message:
        if t.base in ("float32", "float64"):
            return lambda v: check_float(v, where, t.base)
        if t.base == "bool":
            return lambda v: check_bool(v, where)
        if t.is_string:
            return lambda v: check_str(v, where, t.string_bound or 0)
        return lambda v: check_int(v, where, t.base)
    if t.kind == SCALAR:
        nested = field_classes[i]
        return lambda v: check_message(v, nested, where)
    if t.is_primitive:
        dtype = _DTYPES[t.base]
        if t.kind == ARRAY:
            return lambda v: checked_fixed_array(v, dtype, t.count, where)
        return lambda v: checked_array(v, dtype, where)
    if t.is_string:
        return lambda v: check_list(v, str, where, "str")
    item = field_classes[i]
    return lambda v: check_list(v, item, where, t.base)


def _install_checks(cls: Any) -> None:
    checkers = {f.name: _field_checker(cls._spec, i, cls._field_classes) for i, f in enumerate(cls._spec.fields)}
    get_checker = checkers.get
    set_field = object.__setattr__

    def __setattr__(self: Any, name: str, value: Any) -> None:
        check = get_checker(name)
        set_field(self, name, value if check is None else check(value))

    cls.__setattr__ = __setattr__


def _message_class(spec: MsgSpec, get: Callable[[str], type], qualname: str) -> type:
    ns: dict[str, Any] = {
        "_Message": Message, "_zeros": np.zeros, "_empty": np.empty, "_arr": as_array,
        "_farr": as_fixed_array, "_aeq": np.array_equal, "_chf": check_float, "_chi": check_int,
        "_chb": check_bool, "_chs": check_str, "_chm": check_message, "_chl": check_list,
        "_carr": checked_array, "_cfarr": checked_fixed_array,
    }
    source, freeze = _class_source(spec, ns, get)
    code = compile(source, f"<aiorobot.msgs {spec.name}>", "exec")
    exec(code, ns)  # noqa: S102 - source generated from a validated spec
    cls: type = ns[spec.short_name]
    ns.update(_Self=cls, _new=object.__new__, _ro=_readonly_array, _FL=FrozenList)
    ns.update({f"_S{i}": cls.__dict__[f.name].__set__ for i, f in enumerate(spec.fields)})
    exec(compile(freeze, f"<aiorobot.msgs {spec.name} freeze>", "exec"), ns)  # noqa: S102
    cls._fz = staticmethod(ns["_fz"])  # type: ignore[attr-defined]
    cls._cp = staticmethod(ns["_cp"])  # type: ignore[attr-defined]
    cls._base = cls  # type: ignore[attr-defined]
    cls._frozen = False  # type: ignore[attr-defined]
    cls.__module__ = f"aiorobot.msgs.{spec.package}"
    cls.__qualname__ = qualname
    cls.__doc__ = f"ROS 2 message {spec.name}."
    cls._field_types = {f.name: str(f.type) for f in spec.fields}  # type: ignore[attr-defined]
    cls._spec = spec  # type: ignore[attr-defined]
    cls._field_classes = {i: ns[f"_T{i}"] for i in range(len(spec.fields)) if f"_T{i}" in ns}  # type: ignore[attr-defined]
    _CLASSES.append(cls)
    if _CHECK_USERS:
        _install_checks(cls)
    return cls


def _namespace(cls_name: str, base: type, msgtype: str, package: str, qualname: str,
               members: dict[str, Any]) -> type:
    cls = _InterfaceMeta(cls_name, (base,), {"__msgtype__": msgtype, "__slots__": (), **members})
    cls.__module__ = f"aiorobot.msgs.{package}"
    cls.__qualname__ = qualname
    return cls


def build_class(spec: Any, get: Callable[[str], type]) -> type:
    """Build the class for a MsgSpec, ServiceSpec or ActionSpec (parts via ``get``)."""
    from ._registry import ActionSpec, ServiceSpec

    pkg, kind, short = spec.name.split("/")
    if isinstance(spec, MsgSpec):
        if kind == "msg":
            return _message_class(spec, get, short)
        from ._registry import _owner

        owner = get(_owner(spec.name))  # building the owner builds and caches this part
        for cls in _walk(owner):
            if getattr(cls, "__msgtype__", None) == spec.name:
                return cls
        raise LookupError(f"{spec.name} is not part of {owner.__msgtype__}")  # pragma: no cover
    if isinstance(spec, ServiceSpec):
        owner_short = spec.name.rsplit("/", 1)[1]
        qual = owner_short if kind == "srv" else ".".join(owner_short.rsplit("_", 1))
        parts = {
            "Request": _message_class(spec.request, get, f"{qual}.Request"),
            "Response": _message_class(spec.response, get, f"{qual}.Response"),
        }
        parts["Event"] = _message_class(spec.event, _with(get, parts), f"{qual}.Event")
        return _namespace(qual.rsplit(".", 1)[-1], Service, spec.name, pkg, qual, parts)
    assert isinstance(spec, ActionSpec)
    members: dict[str, Any] = {
        "Goal": _message_class(spec.goal, get, f"{short}.Goal"),
        "Result": _message_class(spec.result, get, f"{short}.Result"),
        "Feedback": _message_class(spec.feedback, get, f"{short}.Feedback"),
    }
    local = _with(get, members)
    members["SendGoal"] = build_class(spec.send_goal, local)
    members["GetResult"] = build_class(spec.get_result, local)
    members["FeedbackMessage"] = _message_class(spec.feedback_message, local,
                                                f"{short}.FeedbackMessage")
    return _namespace(short, Action, spec.name, pkg, short, members)


def _with(get: Callable[[str], type], parts: dict[str, Any]) -> Callable[[str], type]:
    """A ``get`` that also knows classes being built (not yet in the registry)."""
    by_name = {}
    for cls in parts.values():
        for c in _walk(cls):
            by_name[c.__msgtype__] = c

    def local_get(name: str) -> type:
        return by_name.get(name) or get(name)

    return local_get


def _walk(cls: type) -> list[type]:
    out = [cls]
    for attr in ("Request", "Response", "Event", "Goal", "Result", "Feedback", "SendGoal",
                 "GetResult", "FeedbackMessage"):
        sub = cls.__dict__.get(attr)
        if sub is not None:
            out += _walk(sub)
    return out
