"""Colour-blob detection: HSV threshold + contours (the simple OpenCV example)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

__all__ = ["Blob", "detect_blobs"]


@dataclass(frozen=True)
class Blob:
    """A connected region inside the HSV range: centroid (x, y) pixels, area pixels, bounding box (x, y, w, h)."""

    centroid: tuple[float, float]
    area: float
    bbox: tuple[int, int, int, int]


def detect_blobs(
    image: NDArray[np.uint8],
    hsv_low: tuple[int, int, int],
    hsv_high: tuple[int, int, int],
    min_area: float = 20.0,
) -> list[Blob]:
    """Blobs of an RGB image (H, W, 3) whose HSV (OpenCV ranges: H 0-179) lies in [low, high], largest first."""
    import cv2

    hsv = cv2.cvtColor(image, cv2.COLOR_RGB2HSV)
    mask = cv2.inRange(hsv, np.array(hsv_low, np.uint8), np.array(hsv_high, np.uint8))
    contours, _ = cv2.findContours(mask, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_SIMPLE)
    blobs = []
    for contour in contours:
        moments = cv2.moments(contour)
        area = moments["m00"]
        if area < min_area:
            continue
        x, y, w, h = cv2.boundingRect(contour)
        blobs.append(Blob((moments["m10"] / area, moments["m01"] / area), float(area), (x, y, w, h)))
    return sorted(blobs, key=lambda b: -b.area)
