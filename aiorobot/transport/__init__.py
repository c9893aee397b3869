"""Transports that carry a runtime's graph beyond one process.

``ZenohTransport`` speaks rmw_zenoh's wire format (key expressions, liveliness
tokens, attachments, CDR), so aiorobot processes and ROS 2 nodes running
``rmw_zenoh_cpp`` share one graph. zenoh itself is imported only when a session opens.
"""

from __future__ import annotations

from ._zenoh import TransportStatistics, ZenohTransport

__all__ = ["TransportStatistics", "ZenohTransport"]
