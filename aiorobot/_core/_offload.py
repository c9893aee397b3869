"""Calls into the process pool, with large numpy arrays carried in shared memory.

``Node.offload(fn, *args)`` pickles the call itself, before the pool does. A
numpy array of at least :data:`SHM_THRESHOLD_BYTES` anywhere in the arguments
(an image, a message's ``data`` field) is copied once into a POSIX shared-memory
segment and only its name crosses the pipe; the receiving process copies it out
and unlinks the segment. Results travel back the same way. The receiver always
owns the unlink, and the pool's processes share the parent's resource tracker
(forkserver), so nothing is leaked or reported as leaked.
"""

from __future__ import annotations

import io
import pickle
import sys
from collections.abc import Callable
from multiprocessing.shared_memory import SharedMemory
from typing import Any

__all__ = ["SHM_THRESHOLD_BYTES", "dumps", "loads", "run_call"]

#: Arrays this large or larger cross process boundaries in shared memory.
SHM_THRESHOLD_BYTES = 64 * 1024


class _Pickler(pickle.Pickler):
    """Pickles large numpy arrays as shared-memory segments."""

    def __init__(self, file: io.BytesIO, segments: list[str]) -> None:
        super().__init__(file, protocol=pickle.HIGHEST_PROTOCOL)
        self.segments = segments

    def reducer_override(self, obj: Any) -> Any:
        np = sys.modules.get("numpy")
        if (
            np is None
            or type(obj) is not np.ndarray
            or obj.nbytes < SHM_THRESHOLD_BYTES
            or obj.dtype.hasobject
        ):
            return NotImplemented
        shm = SharedMemory(create=True, size=obj.nbytes)
        try:
            view = np.ndarray(obj.shape, obj.dtype, buffer=shm.buf)
            view[...] = obj
            del view
        finally:
            shm.close()
        self.segments.append(shm.name)
        return _attach, (shm.name, obj.shape, obj.dtype.str)


def _attach(name: str, shape: tuple[int, ...], dtype: str) -> Any:
    """Copy a shared array out of its segment and unlink it (the receiver owns the unlink)."""
    import numpy as np

    shm = SharedMemory(name=name)
    try:
        array = np.ndarray(shape, np.dtype(dtype), buffer=shm.buf).copy()
    finally:
        shm.close()
        shm.unlink()
    return array


def dumps(obj: Any) -> tuple[bytes, list[str]]:
    """Pickle ``obj``; large arrays go to shared memory. Returns the bytes and the segment names."""
    buffer = io.BytesIO()
    segments: list[str] = []
    try:
        _Pickler(buffer, segments).dump(obj)
    except BaseException:
        release(segments)
        raise
    return buffer.getvalue(), segments


def loads(data: bytes) -> Any:
    return pickle.loads(data)


def release(segments: list[str]) -> None:
    """Unlink segments nobody received (a failed or abandoned call)."""
    for name in segments:
        try:
            shm = SharedMemory(name=name)
        except FileNotFoundError:
            continue  # the receiver copied it out already
        shm.close()
        shm.unlink()


def run_call(payload: bytes) -> bytes:
    """The pool-side half of ``offload``: unpickle the call, run it, pickle the result."""
    fn, args, kwargs = loads(payload)
    result = _call(fn, args, kwargs)
    data, _ = dumps(result)
    return data


def _call(fn: Callable[..., Any], args: tuple[Any, ...], kwargs: dict[str, Any]) -> Any:
    return fn(*args, **kwargs)
