"""Image encodings and conversions between them, as cv_bridge's C++ core does them.

``sensor_msgs/image_encodings.hpp`` (colour, mono, Bayer and YUV encodings, the generic
``8UC3``-style ones, their channel counts and bit depths) and cv_bridge's ``getCvType``,
conversion table and ``cvtColor`` (colour conversions with OpenCV, then 8 <-> 16 bit
scaling by 65535/255 when the depth changes). Errors are :class:`CvBridgeError` with
upstream's words. OpenCV types are made with ``cv2.CV_MAKETYPE``, so they are those of the
installed OpenCV (4.x and 5.x number them differently).
"""

from __future__ import annotations

import re
from functools import cache
from typing import Any

import numpy as np

__all__ = [
    "CvBridgeError", "bit_depth", "cv_type", "cvt_color", "depth_and_channels", "get_cv_type",
    "is_bayer", "is_color", "is_mono", "num_channels",
]


class CvBridgeError(TypeError):
    """This is the error raised by :class:`cv_bridge.CvBridge` methods when they fail."""


#: OpenCV depth name -> (depth number, numpy dtype name)
DEPTHS: dict[str, tuple[int, str]] = {
    "8U": (0, "uint8"), "8S": (1, "int8"), "16U": (2, "uint16"), "16S": (3, "int16"),
    "32S": (4, "int32"), "32F": (5, "float32"), "64F": (6, "float64"),
}
#: the named encodings cv_bridge knows: encoding -> (depth name, channels)
_NAMED: dict[str, tuple[str, int]] = {
    "bgr8": ("8U", 3), "mono8": ("8U", 1), "rgb8": ("8U", 3), "mono16": ("16U", 1),
    "bgr16": ("16U", 3), "rgb16": ("16U", 3), "bgra8": ("8U", 4), "rgba8": ("8U", 4),
    "bgra16": ("16U", 4), "rgba16": ("16U", 4),
    "bayer_rggb8": ("8U", 1), "bayer_bggr8": ("8U", 1), "bayer_gbrg8": ("8U", 1), "bayer_grbg8": ("8U", 1),
    "bayer_rggb16": ("16U", 1), "bayer_bggr16": ("16U", 1), "bayer_gbrg16": ("16U", 1),
    "bayer_grbg16": ("16U", 1),
    # yuv422 and yuv422_yuy2 are the deprecated names of uyvy and yuyv
    "yuv422": ("8U", 2), "yuv422_yuy2": ("8U", 2), "uyvy": ("8U", 2), "yuyv": ("8U", 2),
}
_GENERIC = re.compile(r"(8U|8S|16U|16S|32S|32F|64F)(?:C([0-9]+))?")
_ABSTRACT = re.compile(r"(8|16|32|64)(U|S|F)C([0-9]*)")  # image_encodings' cv_type_regex
_COLOR = {"rgb8", "bgr8", "rgba8", "bgra8", "rgb16", "bgr16", "rgba16", "bgra16",
          "yuv422", "yuv422_yuy2", "uyvy", "yuyv", "nv21", "nv24"}
_YUV = {"yuv422", "yuv422_yuy2", "uyvy", "yuyv", "nv21", "nv24"}


def is_color(encoding: str) -> bool:
    return encoding in _COLOR


def is_mono(encoding: str) -> bool:
    return encoding in ("mono8", "mono16")


def is_bayer(encoding: str) -> bool:
    return encoding.startswith("bayer_") and encoding in _NAMED


def num_channels(encoding: str) -> int:
    """Channels of ``encoding`` (image_encodings::numChannels)."""
    if encoding in _NAMED and encoding not in _YUV:
        return _NAMED[encoding][1]
    m = _ABSTRACT.fullmatch(encoding)
    if m:
        return int(m.group(3)) if m.group(3) else 1
    if encoding in _YUV:
        return 2
    raise CvBridgeError(f"Unknown encoding {encoding}")


def bit_depth(encoding: str) -> int:
    """Bits per channel of ``encoding`` (image_encodings::bitDepth)."""
    if encoding in _NAMED:
        return 8 if _NAMED[encoding][0] == "8U" else 16
    m = _ABSTRACT.fullmatch(encoding)
    if m:
        return int(m.group(1))
    if encoding in _YUV:
        return 8
    raise CvBridgeError(f"Unknown encoding {encoding}")


def depth_and_channels(encoding: str) -> tuple[str, int]:
    """The OpenCV depth name and channel count of ``encoding`` (cv_bridge::getCvType)."""
    if encoding in _NAMED:
        return _NAMED[encoding]
    m = _GENERIC.fullmatch(encoding)
    if m and (m.group(2) is None or int(m.group(2)) > 0):
        return m.group(1), int(m.group(2) or 1)
    raise CvBridgeError(f"Unrecognized image encoding [{encoding}]")


def cv_type(depth: str, channels: int) -> int:
    """The installed OpenCV's type number of ``depth`` (``'8U'``...) with ``channels``."""
    import cv2

    return int(cv2.CV_MAKETYPE(DEPTHS[depth][0], channels))


def get_cv_type(encoding: str) -> int:
    """cv_bridge's ``getCvType``: the OpenCV type of ``encoding`` (CvBridgeError if unknown)."""
    return cv_type(*depth_and_channels(encoding))


# cv_bridge's colour families (getEncoding) and conversion table (getConversionCodes)
_FAMILY = {
    "mono8": "GRAY", "mono16": "GRAY", "bgr8": "BGR", "bgr16": "BGR", "rgb8": "RGB", "rgb16": "RGB",
    "bgra8": "BGRA", "bgra16": "BGRA", "rgba8": "RGBA", "rgba16": "RGBA",
    "yuv422": "UYVY", "uyvy": "UYVY", "yuv422_yuy2": "YUY2", "yuyv": "YUY2",
    "bayer_rggb8": "BAYER_RGGB", "bayer_rggb16": "BAYER_RGGB", "bayer_bggr8": "BAYER_BGGR",
    "bayer_bggr16": "BAYER_BGGR", "bayer_gbrg8": "BAYER_GBRG", "bayer_gbrg16": "BAYER_GBRG",
    "bayer_grbg8": "BAYER_GRBG", "bayer_grbg16": "BAYER_GRBG",
}
_SAME = None  # a depth change with the channels kept (cv_bridge's SAME_FORMAT)


@cache
def _conversions() -> dict[tuple[str, str], int | None]:
    import cv2

    colours = ("GRAY", "RGB", "BGR", "RGBA", "BGRA")
    table: dict[tuple[str, str], int | None] = {(f, f): _SAME for f in (*colours, "UYVY")}
    for src in colours:
        for dst in colours:
            if src != dst:
                table[(src, dst)] = getattr(cv2, f"COLOR_{src}2{dst}")
    for family, suffix in (("UYVY", "UYVY"), ("YUY2", "YUY2")):
        for dst in colours:
            table[(family, dst)] = getattr(cv2, f"COLOR_YUV2{dst}_{suffix}")
    # OpenCV names a Bayer pattern by its second row: ROS's RGGB is OpenCV's BG
    for family, cv_name in (("BAYER_RGGB", "BG"), ("BAYER_BGGR", "RG"), ("BAYER_GBRG", "GR"),
                            ("BAYER_GRBG", "GB")):
        for dst in ("GRAY", "RGB", "BGR"):
            table[(family, dst)] = getattr(cv2, f"COLOR_Bayer{cv_name}2{dst}")
    return table


def _is_colour_format(encoding: str) -> bool:
    return is_color(encoding) or is_mono(encoding) or is_bayer(encoding)


def conversion_codes(src: str, dst: str) -> list[int | None]:
    """The OpenCV conversions from ``src`` to ``dst`` (None: a depth change), or CvBridgeError."""
    same_channels = num_channels(src) == num_channels(dst)
    if not _is_colour_format(src):
        if _is_colour_format(dst):
            raise CvBridgeError(f"[{src}] is not a color format. but [{dst}] is. The conversion does not make sense")
        if not same_channels:
            raise CvBridgeError(f"[{src}] and [{dst}] do not have the same number of channel")
        return [_SAME]
    if not _is_colour_format(dst):
        if not same_channels:
            raise CvBridgeError(f"[{src}] is a color format but [{dst}] is not so they must have the same "
                                "OpenCV type, CV_8UC3, CV16UC1 ....")
        return [_SAME]
    code = _conversions().get((_FAMILY.get(src, ""), _FAMILY.get(dst, "")), -1)
    if code == -1:
        raise CvBridgeError(f"Unsupported conversion from [{src}] to [{dst}]")
    codes: list[int | None] = [code]
    if bit_depth(src) != bit_depth(dst) and _FAMILY.get(src) != _FAMILY.get(dst):
        codes.append(_SAME)
    return codes


def cvt_color(image: np.ndarray[Any, Any], src: str, dst: str) -> np.ndarray[Any, Any]:
    """``image`` in encoding ``src`` converted to ``dst`` (cv_bridge's cvtColor / toCvCopy)."""
    import cv2

    if not dst or dst == src:
        return image.copy()
    out = image
    for code in conversion_codes(src, dst):
        try:
            if code is _SAME:
                dtype = np.dtype(DEPTHS[depth_and_channels(dst)[0]][1])
                src_bits, dst_bits = bit_depth(src), bit_depth(dst)
                if src_bits == 8 and dst_bits == 16:
                    out = _convert(out, dtype, 65535.0 / 255.0)
                elif src_bits == 16 and dst_bits == 8:
                    out = _convert(out, dtype, 255.0 / 65535.0)
                else:
                    out = _convert(out, dtype, 1.0)
            else:
                out = cv2.cvtColor(out, code)
        except cv2.error as err:
            raise CvBridgeError(f"cannot convert [{src}] to [{dst}]: {str(err).strip()}") from None
    return out


def _convert(image: np.ndarray[Any, Any], dtype: np.dtype[Any], scale: float) -> np.ndarray[Any, Any]:
    """OpenCV's ``Mat::convertTo(dst, type, scale)``: scaled, rounded, saturated to ``dtype``."""
    if image.dtype == dtype and scale == 1.0:
        return image.copy()
    values = image.astype(np.float64) * scale
    if np.issubdtype(dtype, np.integer):
        info = np.iinfo(dtype)
        values = np.clip(np.rint(values), info.min, info.max)
    return values.astype(dtype)
