"""``cv_bridge.CvBridge``: sensor_msgs Image / CompressedImage <-> OpenCV images (numpy arrays).

Upstream's Python API (ros-perception/vision_opencv, cv_bridge/python/cv_bridge/core.py) over
aiorobot.msgs' sensor_msgs, with the C++ core's encodings and conversions restated in
:mod:`._encodings`. Differences: an image whose dtype has no OpenCV depth (``int64``,
``bool``...) raises :class:`CvBridgeError` naming it (upstream: ``KeyError``); a message whose
data is shorter than ``height * step`` raises :class:`CvBridgeError` (upstream: numpy's
``TypeError``); ``CvBridgeError`` is a ``TypeError`` in both.
"""

from __future__ import annotations

import sys
from typing import Any

import numpy as np

from ._encodings import DEPTHS, CvBridgeError, cv_type, cvt_color, depth_and_channels, get_cv_type

__all__ = ["CvBridge", "CvBridgeError"]

_CHANNEL_SHIFT_CACHE: list[int] = []


def _channel_shift() -> int:
    if not _CHANNEL_SHIFT_CACHE:
        _CHANNEL_SHIFT_CACHE.append((cv_type("8U", 2) - cv_type("8U", 1)).bit_length() - 1)
    return _CHANNEL_SHIFT_CACHE[0]


def _data_bytes(data: Any) -> bytes | memoryview:
    if isinstance(data, (bytes, bytearray, memoryview)):
        return data
    if isinstance(data, np.ndarray):
        return memoryview(np.ascontiguousarray(data, dtype=np.uint8)).cast("B")
    return bytes(bytearray(data))


class CvBridge:
    """Converts between OpenCV images (numpy arrays) and ROS Image / CompressedImage messages."""

    def __init__(self) -> None:
        self.cvtype_to_name: dict[int, str] = {}
        self.cvdepth_to_numpy_depth: dict[int, str] = {number: dtype for number, dtype in DEPTHS.values()}
        for depth in DEPTHS:
            for channels in (1, 2, 3, 4):
                self.cvtype_to_name[cv_type(depth, channels)] = f"{depth}C{channels}"
        self.numpy_type_to_cvtype: dict[str, str] = {dtype: depth for depth, (_, dtype) in DEPTHS.items()}
        self.numpy_type_to_cvtype.update({v: k for k, v in list(self.numpy_type_to_cvtype.items())})

    # --- encodings -------------------------------------------------------------------------
    def dtype_with_channels_to_cvtype2(self, dtype: np.dtype[Any], n_channels: int) -> str:
        depth = self.numpy_type_to_cvtype.get(np.dtype(dtype).name)
        if depth is None or depth not in DEPTHS:
            raise CvBridgeError(
                f"image dtype {np.dtype(dtype).name} has no OpenCV depth; expected one of "
                f"{', '.join(d for _, d in DEPTHS.values())}")
        return f"{depth}C{n_channels}"

    def cvtype2_to_dtype_with_channels(self, cvtype: int) -> tuple[str, int]:
        shift = _channel_shift()
        return self.cvdepth_to_numpy_depth[cvtype & ((1 << shift) - 1)], (cvtype >> shift) + 1

    def encoding_to_cvtype2(self, encoding: str) -> int:
        return get_cv_type(encoding)

    def encoding_to_dtype_with_channels(self, encoding: str) -> tuple[str, int]:
        depth, channels = depth_and_channels(encoding)
        return DEPTHS[depth][1], channels

    # --- Image -----------------------------------------------------------------------------
    def imgmsg_to_cv2(self, img_msg: Any, desired_encoding: str = "passthrough") -> np.ndarray[Any, Any]:
        """The image of a ``sensor_msgs/msg/Image`` as a numpy array (a copy).

        Shape ``(height, width)`` for one channel, ``(height, width, channels)`` otherwise;
        ``desired_encoding`` ``'passthrough'`` keeps the message's encoding, another standard
        encoding converts (``CvBridgeError`` when that is not possible).
        """
        dtype_name, n_channels = self.encoding_to_dtype_with_channels(img_msg.encoding)
        dtype = np.dtype(dtype_name).newbyteorder(">" if img_msg.is_bigendian else "<")
        data = _data_bytes(img_msg.data)
        height, width, step = int(img_msg.height), int(img_msg.width), int(img_msg.step)
        if step < width * dtype.itemsize * n_channels:
            raise CvBridgeError(
                f"Image is wrongly formed: step < width * byte_depth * num_channels  or  {step} != "
                f"{width} * {dtype.itemsize} * {n_channels}")
        if len(data) < height * step:
            raise CvBridgeError(f"Image is wrongly formed: height * step != size  or  {height} * {step} != {len(data)}")
        row = step // dtype.itemsize
        if n_channels == 1:
            im = np.ndarray(shape=(height, row), dtype=dtype, buffer=data, strides=(step, dtype.itemsize))
            im = np.ascontiguousarray(im[:height, :width])
        else:
            im = np.ndarray(shape=(height, row // n_channels, n_channels), dtype=dtype, buffer=data,
                            strides=(step, dtype.itemsize * n_channels, dtype.itemsize))
            im = np.ascontiguousarray(im[:height, :width, :])
        if bool(img_msg.is_bigendian) == (sys.byteorder == "little"):
            im = im.byteswap().view(dtype.newbyteorder("="))
        if desired_encoding == "passthrough":
            return im
        return cvt_color(im, img_msg.encoding, desired_encoding)

    def cv2_to_imgmsg(self, cvim: Any, encoding: str = "passthrough", header: Any = None) -> Any:
        """A ``sensor_msgs/msg/Image`` of numpy image ``cvim``.

        ``encoding`` ``'passthrough'`` names the image's OpenCV type (``8UC3``...); another
        encoding must have the image's type (``CvBridgeError`` otherwise).
        """
        from aiorobot.msgs.sensor_msgs import Image

        if not isinstance(cvim, (np.ndarray, np.generic)):
            raise TypeError("Your input type is not a numpy array")
        img_msg = Image()
        img_msg.height = int(cvim.shape[0])
        img_msg.width = int(cvim.shape[1])
        if header is not None:
            img_msg.header = header
        channels = 1 if len(cvim.shape) < 3 else int(cvim.shape[2])
        cv_type_name = self.dtype_with_channels_to_cvtype2(cvim.dtype, channels)
        if encoding == "passthrough":
            img_msg.encoding = cv_type_name
        else:
            img_msg.encoding = encoding
            depth, n = depth_and_channels(encoding)
            if f"{depth}C{n}" != cv_type_name:
                raise CvBridgeError(
                    f"encoding specified as {encoding}, but image has incompatible type {cv_type_name}")
        if cvim.dtype.byteorder == ">" or (cvim.dtype.byteorder == "=" and sys.byteorder == "big"):
            img_msg.is_bigendian = True
        img_msg.data = np.frombuffer(cvim.tobytes(), dtype=np.uint8)
        img_msg.step = len(img_msg.data) // img_msg.height if img_msg.height else 0
        return img_msg

    # --- CompressedImage -------------------------------------------------------------------
    def compressed_imgmsg_to_cv2(self, cmprs_img_msg: Any, desired_encoding: str = "passthrough") -> np.ndarray[Any, Any]:
        """The image of a ``sensor_msgs/msg/CompressedImage`` (decoded by OpenCV, colour as bgr8)."""
        import cv2

        buf = np.frombuffer(_data_bytes(cmprs_img_msg.data), dtype=np.uint8)
        im = cv2.imdecode(buf, cv2.IMREAD_UNCHANGED) if buf.size else None
        if im is None:
            raise CvBridgeError(f"cannot decode the compressed image ({buf.size} bytes, format "
                                f"{cmprs_img_msg.format!r}): OpenCV read no image from it")
        if desired_encoding == "passthrough":
            return im
        return cvt_color(im, "bgr8", desired_encoding)

    def cv2_to_compressed_imgmsg(self, cvim: Any, dst_format: str = "jpg") -> Any:
        """A ``sensor_msgs/msg/CompressedImage`` of ``cvim`` encoded by OpenCV as ``dst_format``."""
        import cv2

        from aiorobot.msgs.sensor_msgs import CompressedImage

        if not isinstance(cvim, (np.ndarray, np.generic)):
            raise TypeError("Your input type is not a numpy array")
        msg = CompressedImage()
        msg.format = dst_format
        try:
            ok, encoded = cv2.imencode("." + dst_format, cvim)
        except cv2.error as err:
            raise CvBridgeError(f"cannot encode the image as {dst_format!r}: {str(err).strip()}") from None
        if not ok:
            raise CvBridgeError(f"cannot encode the image as {dst_format!r}: OpenCV refused it")
        msg.data = np.asarray(encoded, dtype=np.uint8).reshape(-1)
        return msg
