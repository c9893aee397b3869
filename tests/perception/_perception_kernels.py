"""Kernels the pipeline tests run in worker processes (importable by module name there)."""

from __future__ import annotations

import os
import threading

import numpy as np

from aiorobot.msgs.std_msgs import Header, String
from aiorobot.perception import BadInput


def mean_and_pid(pixels, frame):
    """Publishes 'pid mean shape frame_id' for each frame."""
    return String(data=f"{os.getpid()} {float(pixels.mean()):.3f} {pixels.shape} {frame.header.frame_id}")


def hang_on_marker(pixels, frame):
    """Blocks forever on a frame whose first pixel is 255 (to be killed mid-frame), else echoes the first pixel."""
    if pixels.flat[0] == 255:
        threading.Event().wait()
    return String(data=str(int(pixels.flat[0])))


def strict(pixels, frame):
    """Rejects odd first pixels as bad input, raises on 13, dies on 99, returns None on 0."""
    value = int(pixels.flat[0])
    if value == 13:
        raise RuntimeError("unlucky frame")
    if value == 99:
        os._exit(3)
    if value == 0:
        return None
    if value % 2:
        raise BadInput(f"odd first pixel {value}")
    return String(data=str(value))


def wrong_type(pixels, frame):
    return Header(frame_id="not a String")


def first_pixel(pixels, frame):
    return String(data=str(int(pixels.flat[0])))


def gated(pixels, frame):
    """Waits until the file named in frame.context exists, then echoes the first pixel (back-pressure tests)."""
    import time

    while frame.context and not os.path.exists(frame.context):
        time.sleep(0.005)
    return String(data=str(int(np.asarray(pixels).flat[0])))


class Unimportable:
    """A kernel whose class cannot be found by the workers: each one exits at start."""

    def __call__(self, pixels, frame):
        return None

    def __reduce__(self):
        return (_missing_in_workers, ())


def _missing_in_workers():
    raise ImportError("this kernel cannot be rebuilt in a worker")
