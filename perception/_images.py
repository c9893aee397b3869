"""Checked numpy views of ``sensor_msgs/Image`` data, and camera matrices from ``CameraInfo``."""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = ["BadInput", "ENCODINGS", "camera_matrix_from_info", "image_array"]

#: encoding -> (channels, dtype) for the encodings the kernels read.
ENCODINGS: dict[str, tuple[int, str]] = {
    "rgb8": (3, "u1"),
    "bgr8": (3, "u1"),
    "mono8": (1, "u1"),
    "rgba8": (4, "u1"),
    "bgra8": (4, "u1"),
}


class BadInput(ValueError):
    """A message whose fields disagree with its data: the frame is dropped and counted."""


def image_array(msg: Any) -> NDArray[np.uint8]:
    """View an Image's data as ``(height, width, channels)`` without copying.

    Raises :class:`BadInput` when the encoding is unknown, the image is empty, or
    ``step``/``height``/``width`` disagree with the length of ``data``.
    """
    encoding = msg.encoding
    if encoding not in ENCODINGS:
        raise BadInput(f"image encoding {encoding!r} is not one of {sorted(ENCODINGS)}")
    channels, dtype = ENCODINGS[encoding]
    height, width, step = int(msg.height), int(msg.width), int(msg.step)
    data = np.asarray(msg.data, dtype=np.uint8)
    if height == 0 or width == 0 or data.size == 0:
        raise BadInput(f"empty image: {width}x{height} with {data.size} data bytes")
    if step < width * channels:
        raise BadInput(f"image step {step} is shorter than width*channels = {width}*{channels} = {width * channels} "
                       f"for encoding {encoding!r}")
    if data.size != step * height:
        raise BadInput(f"image data has {data.size} bytes, expected step*height = {step}*{height} = {step * height}")
    rows = data.reshape(height, step)[:, : width * channels]
    return rows.reshape(height, width, channels)


def camera_matrix_from_info(info: Any) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``(K 3x3, distortion coefficients)`` from a ``sensor_msgs/CameraInfo``.

    Raises :class:`BadInput` when K is zero or not 9 numbers (an unset CameraInfo).
    """
    k = np.asarray(info.k, dtype=np.float64)
    if k.shape != (9,) or not np.all(np.isfinite(k)) or k[0] <= 0.0 or k[4] <= 0.0:
        raise BadInput(f"camera_info K must be 9 finite numbers with fx, fy > 0, got {k.tolist()}")
    d = np.asarray(info.d, dtype=np.float64)
    if d.size == 0:
        d = np.zeros(5)
    return k.reshape(3, 3), d
