"""A ring of fixed-size frame slots in one POSIX shared-memory segment: one writer, worker readers.

The writer (the pipeline, in the main process) owns the segment and the slot
bookkeeping: :meth:`FrameRing.acquire` hands out a free slot, :meth:`write`
copies a frame into it once, the slot's index and the frame's shape cross to a
worker over a pipe, and the worker reads the frame in place through
:func:`attach_view` (a numpy view, no pickle, no copy). The writer
:meth:`release`\\ s the slot when the worker reports it is done, or when the
worker died. :meth:`close` unlinks the segment: nothing stays in ``/dev/shm``.
"""

from __future__ import annotations

from multiprocessing.shared_memory import SharedMemory
from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = ["FrameRing", "RingAttachment"]


class FrameRing:
    """``slots`` slots of ``slot_bytes`` bytes each, in one shared-memory segment (the writer's side)."""

    def __init__(self, slots: int, slot_bytes: int) -> None:
        if slots < 1 or slot_bytes < 1:
            raise ValueError(f"a FrameRing needs slots >= 1 and slot_bytes >= 1, got slots={slots}, "
                             f"slot_bytes={slot_bytes}")
        self.slots = slots
        self.slot_bytes = slot_bytes
        self._shm: SharedMemory | None = SharedMemory(create=True, size=slots * slot_bytes)
        self.name = self._shm.name
        self._free = list(range(slots - 1, -1, -1))
        self._busy: set[int] = set()

    def __repr__(self) -> str:
        state = "closed" if self._shm is None else f"busy={len(self._busy)}"
        return f"<FrameRing {self.name} slots={self.slots} slot_bytes={self.slot_bytes} {state}>"

    @property
    def free_slots(self) -> int:
        return len(self._free)

    def acquire(self) -> int | None:
        """A free slot's index, or None when every slot holds a frame."""
        if self._shm is None:
            raise RuntimeError(f"{self!r} is closed")
        if not self._free:
            return None
        slot = self._free.pop()
        self._busy.add(slot)
        return slot

    def release(self, slot: int) -> None:
        """Give ``slot`` back (its reader is done with it, or died)."""
        if slot not in self._busy:
            raise ValueError(f"slot {slot} of {self!r} is not in use")
        self._busy.remove(slot)
        self._free.append(slot)

    def write(self, slot: int, frame: NDArray[Any]) -> tuple[tuple[int, ...], str]:
        """Copy ``frame`` into ``slot`` (its only copy); returns the (shape, dtype) a reader needs."""
        if self._shm is None:
            raise RuntimeError(f"{self!r} is closed")
        if frame.nbytes > self.slot_bytes:
            raise ValueError(f"a frame of {frame.nbytes} bytes does not fit {self!r}")
        view: NDArray[Any] = np.ndarray(frame.shape, frame.dtype, buffer=self._shm.buf, offset=slot * self.slot_bytes)
        np.copyto(view, frame)
        return frame.shape, frame.dtype.str

    def close(self) -> None:
        """Unlink the segment (idempotent). Readers' views stay valid until they detach."""
        shm, self._shm = self._shm, None
        if shm is not None:
            shm.close()
            try:
                shm.unlink()
            except FileNotFoundError:
                pass

    def __enter__(self) -> FrameRing:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


class RingAttachment:
    """A reader's handle on a writer's ring (in a worker process): in-place numpy views of slots."""

    def __init__(self, name: str, slot_bytes: int) -> None:
        self._shm: SharedMemory | None = SharedMemory(name=name)
        self.slot_bytes = slot_bytes

    def view(self, slot: int, shape: tuple[int, ...], dtype: str) -> NDArray[Any]:
        """The frame in ``slot``, read-only, in place (valid until the slot is released)."""
        assert self._shm is not None
        array: NDArray[Any] = np.ndarray(shape, np.dtype(dtype), buffer=self._shm.buf,
                                         offset=slot * self.slot_bytes)
        array.flags.writeable = False
        return array

    def close(self) -> None:
        shm, self._shm = self._shm, None
        if shm is not None:
            shm.close()
