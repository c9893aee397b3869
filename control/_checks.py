"""Boundary checks shared by the control cores: coerce once, fail with expected vs got."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = ["check_positive", "check_non_negative", "check_vector", "check_limits"]


def check_positive(name: str, value: Any) -> float:
    """Return ``value`` as a float, raising ``ValueError`` unless it is finite and > 0."""
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ValueError(
            f"{name} must be a positive number, got {value!r} of type {type(value).__name__}"
        ) from None
    if not math.isfinite(number) or number <= 0.0:
        raise ValueError(f"{name} must be a finite number > 0, got {value!r}; pass a positive value")
    return number


def check_non_negative(name: str, value: Any) -> float:
    """Return ``value`` as a float, raising ``ValueError`` unless it is finite and >= 0."""
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ValueError(
            f"{name} must be a number >= 0, got {value!r} of type {type(value).__name__}"
        ) from None
    if not math.isfinite(number) or number < 0.0:
        raise ValueError(f"{name} must be a finite number >= 0, got {value!r}")
    return number


def check_vector(name: str, value: Any, length: int) -> NDArray[np.float64]:
    """Coerce ``value`` to a float64 array of shape ``(length,)`` or raise ``ValueError``."""
    array = np.asarray(value, dtype=np.float64)
    if array.shape != (length,):
        raise ValueError(f"{name} must have shape ({length},), got shape {array.shape}")
    return array


def check_limits(name: str, value: Any, length: int) -> NDArray[np.float64]:
    """A per-axis limit: a scalar (same for every axis) or ``(length,)``; every entry > 0 (inf allowed)."""
    array = np.asarray(value, dtype=np.float64)
    if array.ndim == 0:
        array = np.full(length, float(array))
    if array.shape != (length,):
        raise ValueError(f"{name} must be a scalar or have shape ({length},), got shape {array.shape}")
    if np.any(np.isnan(array)) or np.any(array <= 0.0):
        raise ValueError(f"{name} must be > 0 on every axis (inf for no limit), got {array.tolist()}")
    return array
