"""Transports that carry a runtime's graph beyond one process.

``ZenohTransport`` speaks rmw_zenoh's wire format (key expressions, liveliness
tokens, attachments, CDR), so aiorobot processes and ROS 2 nodes running
``rmw_zenoh_cpp`` share one graph. zenoh itself is imported only when a session opens.
``DdsTransport`` speaks ROS 2's DDS conventions on cyclonedds (``rt/`` topics, ``rq/``/``rr/``
services, ``ros_discovery_info``), so it joins a graph of ``rmw_cyclonedds_cpp`` nodes (and
``rmw_fastrtps_cpp`` ones, for topics and the graph): docs/dds.md.
A session's config is checked before zenoh opens (``ZenohConfigError``); a session
zenoh refuses raises ``ZenohSessionError`` (docs/security.md).

Importing this package registers its transports by name with the core's registry
(``Runtime(transport="zenoh")``, ``transport = "dds"`` in a config, ``--transport zenoh``).
"""

from __future__ import annotations

import os
from typing import Any

from .._core._transport import MAX_DOMAIN_ID, register_transport
from ._dds import DdsConfigError, DdsStatistics, DdsTransport
from ._session_config import ZenohConfigError, ZenohSessionError
from ._zenoh import TransportStatistics, ZenohTransport

__all__ = ["DdsConfigError", "DdsStatistics", "DdsTransport", "TransportStatistics", "ZenohConfigError", "ZenohSessionError", "ZenohTransport"]


def _env_domain(domain_id: int) -> int:
    """``ROS_DOMAIN_ID`` in the environment applies when ``domain_id`` is left at 0, as in ROS 2."""
    raw = os.environ.get("ROS_DOMAIN_ID", "").strip()
    if domain_id == 0 and raw:
        if not raw.isdigit() or not 0 <= int(raw) <= MAX_DOMAIN_ID:
            raise ValueError(f"ROS_DOMAIN_ID: expected an int in 0..{MAX_DOMAIN_ID}, found {raw!r}")
        domain_id = int(raw)
    return domain_id


def _zenoh_transport(*, domain_id: int = 0, **options: Any) -> ZenohTransport:
    return ZenohTransport(domain_id=_env_domain(domain_id), **options)


def _dds_transport(*, domain_id: int = 0, **options: Any) -> DdsTransport:
    return DdsTransport(domain_id=_env_domain(domain_id), **options)


register_transport("zenoh", _zenoh_transport)
register_transport("dds", _dds_transport)
