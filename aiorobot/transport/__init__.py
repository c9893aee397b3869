"""Transports that carry a runtime's graph beyond one process.

``ZenohTransport`` speaks rmw_zenoh's wire format (key expressions, liveliness
tokens, attachments, CDR), so aiorobot processes and ROS 2 nodes running
``rmw_zenoh_cpp`` share one graph. zenoh itself is imported only when a session opens.
A session's config is checked before zenoh opens (``ZenohConfigError``); a session
zenoh refuses raises ``ZenohSessionError`` (docs/security.md).

Importing this package registers its transports by name with the core's registry
(``Runtime(transport="zenoh")``, ``transport = "zenoh"``, ``--transport zenoh``).
"""

from __future__ import annotations

import os
from typing import Any

from .._core._transport import MAX_DOMAIN_ID, register_transport
from ._session_config import ZenohConfigError, ZenohSessionError
from ._zenoh import TransportStatistics, ZenohTransport

__all__ = ["TransportStatistics", "ZenohConfigError", "ZenohSessionError", "ZenohTransport"]


def _zenoh_transport(*, domain_id: int = 0, **options: Any) -> ZenohTransport:
    """``ROS_DOMAIN_ID`` in the environment applies when ``domain_id`` is left at 0, as in ROS 2."""
    raw = os.environ.get("ROS_DOMAIN_ID", "").strip()
    if domain_id == 0 and raw:
        if not raw.isdigit() or not 0 <= int(raw) <= MAX_DOMAIN_ID:
            raise ValueError(f"ROS_DOMAIN_ID: expected an int in 0..{MAX_DOMAIN_ID}, found {raw!r}")
        domain_id = int(raw)
    return ZenohTransport(domain_id=domain_id, **options)


register_transport("zenoh", _zenoh_transport)
