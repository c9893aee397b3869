"""Helpers for testing aiorobot nodes with pytest-asyncio."""

from __future__ import annotations

__all__: list[str] = []
