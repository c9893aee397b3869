"""Shared helpers for the aiorobot.msgs tests: random messages and rosbags conversion."""

from __future__ import annotations

import functools
from typing import Any

import numpy as np

import aiorobot.msgs as msgs
from aiorobot.msgs._spec import ARRAY, PRIMITIVES, SCALAR, FieldType

_INT_RANGES = {
    # byte stays below 128: rosbags packs byte as a signed int8
    "byte": (0, 127), "char": (0, 255), "int8": (-128, 127), "uint8": (0, 255),
    "int16": (-(2**15), 2**15 - 1), "uint16": (0, 2**16 - 1),
    "int32": (-(2**31), 2**31 - 1), "uint32": (0, 2**32 - 1),
    "int64": (-(2**63), 2**63 - 1), "uint64": (0, 2**64 - 1),
}
_ALPHABET = "abcxyz /_-.0129ÄéΩ漢🙂"


@functools.cache
def rosbags_store() -> Any:
    from rosbags.typesys import Stores, get_typestore

    return get_typestore(Stores.ROS2_JAZZY)


def random_scalar(base: str, rng: np.random.Generator, string_bound: int = 0) -> Any:
    if base == "bool":
        return bool(rng.integers(2))
    if base in ("float32", "float64"):
        value = float(rng.normal() * 1000)
        return float(np.float32(value)) if base == "float32" else value
    if base in ("string", "wstring"):
        alphabet = _ALPHABET if base == "string" else _ALPHABET[:-1]  # BMP for wstring
        n = int(rng.integers(0, 12))
        if string_bound:
            n = min(n, string_bound // 4)
        return "".join(rng.choice(list(alphabet), n))
    lo, hi = _INT_RANGES[base]
    return int(rng.integers(lo, hi, endpoint=True, dtype=np.int64 if lo < 0 else np.uint64))


def random_value(t: FieldType, rng: np.random.Generator) -> Any:
    if t.kind == SCALAR:
        if t.is_message:
            return random_message(msgs.get(t.base), rng)
        return random_scalar(t.base, rng, t.string_bound)
    if t.kind == ARRAY:
        n = t.count
    else:
        n = int(rng.integers(0, 5))
        if t.count:
            n = min(n, t.count)
    if t.is_primitive:
        dtype = np.dtype(PRIMITIVES[t.base][2])
        return np.array([random_scalar(t.base, rng) for _ in range(n)], dtype=dtype)
    return [random_value(t.element, rng) for _ in range(n)]


def random_message(cls: type, rng: np.random.Generator) -> Any:
    spec = cls._spec  # type: ignore[attr-defined]
    return cls(**{f.name: random_value(f.type, rng) for f in spec.fields})


def to_rosbags(msg: Any) -> Any:
    """The rosbags dataclass instance equal to ``msg``."""
    store = rosbags_store()
    cls = store.types[msg.__msgtype__]
    values = {}
    for f in msg._spec.fields:  # noqa: SLF001
        values[f.name] = _convert(getattr(msg, f.name), f.type)
    return cls(**values)


def _convert(value: Any, t: FieldType) -> Any:
    if t.is_message:
        if t.kind == SCALAR:
            return to_rosbags(value)
        return [to_rosbags(v) for v in value]
    if t.kind != SCALAR and t.is_primitive:
        if t.base == "byte":
            return np.asarray(value).astype(np.int8)
        return np.asarray(value)
    return value
