"""Transports that carry a runtime's graph beyond one process.

``ZenohTransport`` speaks rmw_zenoh's wire format (key expressions, liveliness
tokens, attachments, CDR), so aiorobot processes and ROS 2 nodes running
``rmw_zenoh_cpp`` share one graph. zenoh itself is imported only when a session opens.
A session's config is checked before zenoh opens (``ZenohConfigError``); a session
zenoh refuses raises ``ZenohSessionError`` (docs/security.md).
"""

from __future__ import annotations

from ._session_config import ZenohConfigError, ZenohSessionError
from ._zenoh import TransportStatistics, ZenohTransport

__all__ = ["TransportStatistics", "ZenohConfigError", "ZenohSessionError", "ZenohTransport"]
