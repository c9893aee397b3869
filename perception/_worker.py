"""The worker process side of a pipeline: read frames in place from the ring, run the kernel, reply."""

from __future__ import annotations

import signal
import time
import traceback
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from ._images import BadInput
from ._ring import RingAttachment

__all__ = ["READY", "Frame", "worker_main"]

#: a worker's first message: ``(job, status, result, t_start, t_end)`` with no job, before any job is sent
READY = (-1, "ready", None, 0.0, 0.0)


@dataclass(frozen=True)
class Frame:
    """What a kernel gets besides the pixels: the message header, encoding and the pipeline's context.

    ``context`` is whatever the pipeline's ``context`` callable returned when the
    frame arrived (e.g. the camera matrix from the latest CameraInfo).
    """

    header: Any
    encoding: str
    context: Any


def _header(stamp: tuple[int, int] | None, frame_id: str) -> Any:
    if stamp is None:
        return None
    from aiorobot.msgs.std_msgs import Header

    header = Header(frame_id=frame_id)
    header.stamp.sec, header.stamp.nanosec = stamp
    return header


def worker_main(conn: Any, ring_name: str, slot_bytes: int, kernel: Callable[..., Any]) -> None:
    """Serve jobs ``(job, slot, shape, dtype, stamp, frame_id, encoding, context)`` until the pipe closes or ``None`` arrives.

    First sends :data:`READY`, then replies ``(job, status, result, t_start, t_end)``; ``status`` is ``"ok"``,
    ``"bad"`` (the kernel raised :class:`BadInput`) or ``"error"`` (any other
    exception, with its traceback). A kernel's exception never ends the worker.
    """
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # the parent decides when workers stop
    ring = RingAttachment(ring_name, slot_bytes)
    try:
        conn.send(READY)  # up, the ring attached and the kernel's module imported (it came unpickled)
        while True:
            try:
                job = conn.recv()
            except (EOFError, OSError):
                break
            if job is None:
                break
            job_id, slot, shape, dtype, stamp, frame_id, encoding, context = job
            frame = Frame(_header(stamp, frame_id), encoding, context)
            start = time.monotonic()
            pixels = ring.view(slot, shape, dtype)
            try:
                status, result = "ok", kernel(pixels, frame)
            except BadInput as exc:
                status, result = "bad", str(exc)
            except Exception:
                status, result = "error", traceback.format_exc(limit=-3)
            del pixels
            end = time.monotonic()
            try:
                conn.send((job_id, status, result, start, end))
            except (BrokenPipeError, OSError):
                break
            except Exception:  # an unpicklable result
                conn.send((job_id, "error", f"the kernel's result cannot be pickled: {traceback.format_exc(limit=-1)}",
                           start, end))
    finally:
        try:
            ring.close()
        except BufferError:  # a kernel kept a view of the ring; the process exits anyway
            pass
