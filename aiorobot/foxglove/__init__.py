"""Live view in Foxglove: a WebSocket server exposing every topic, parameters and services."""

from __future__ import annotations

from ._bridge import FoxgloveBridge, FoxgloveStatistics

__all__ = ["FoxgloveBridge", "FoxgloveStatistics"]
