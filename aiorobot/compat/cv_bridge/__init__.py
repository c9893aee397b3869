"""``cv_bridge`` for programs under ``aiorobot exec`` (and natively: ``aiorobot.compat.cv_bridge``).

``CvBridge`` (``imgmsg_to_cv2``, ``cv2_to_imgmsg``, ``compressed_imgmsg_to_cv2``,
``cv2_to_compressed_imgmsg``), ``CvBridgeError`` and ``getCvType``, with upstream's encodings
and conversions. ``cvtColorForDisplay`` is not provided.
"""

from __future__ import annotations

from typing import Any

from .._missing import not_provided
from ._encodings import get_cv_type as getCvType
from .core import CvBridge, CvBridgeError

__all__ = ["CvBridge", "CvBridgeError", "getCvType"]


def __getattr__(name: str) -> Any:
    if name == "cvtColorForDisplay":
        raise not_provided("cv_bridge.cvtColorForDisplay")
    raise AttributeError(f"module 'cv_bridge' has no attribute {name!r}")
