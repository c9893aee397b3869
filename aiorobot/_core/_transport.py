"""The transport seam: how a runtime's in-process bus reaches other processes.

Every runtime has a :class:`~aiorobot._core._bus.Bus` that connects endpoints in its
process zero-copy. A transport extends that bus outwards. It sees every local
endpoint come and go, and it takes part in the bus as ordinary endpoints:

* for a remote subscriber it adds a *tap* on the topic (a subscription whose
  callback runs synchronously in the publishing thread) that serialises and
  sends — only remote endpoints pay for serialisation;
* for a remote publisher it adds a local publisher-side *injector* and publishes
  received, deserialised messages into the bus;
* it adds what it discovers to the graph.

``Node`` never talks to a transport directly, so a networked transport (zenoh)
plugs in without changing it.
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from ._bus import Bus, Endpoint
    from ._graph import NodeInfo
    from ._node import Node

__all__ = ["LocalTransport", "Transport", "make_transport"]


class Transport:
    """Base class of transports; the default methods do nothing."""

    name = "base"

    def __init__(self, *, domain_id: int = 0) -> None:
        self.domain_id = domain_id
        self.bus: Bus | None = None

    async def open(self, bus: Bus) -> None:
        """Attach to ``bus`` (called once by the runtime before any node starts)."""
        self.bus = bus

    async def close(self) -> None:
        """Release every network resource (called once at runtime shutdown)."""
        self.bus = None

    def endpoint_added(self, endpoint: Endpoint) -> None:
        """A local publisher, subscription, service or client appeared (any thread)."""

    def endpoint_removed(self, endpoint: Endpoint) -> None:
        """A local endpoint went away (any thread)."""

    def node_added(self, node: Node) -> None:
        """A local node joined (before its endpoints are added)."""

    def node_removed(self, node: Node) -> None:
        """A local node left (after its endpoints were removed)."""

    def remote_nodes(self) -> tuple[NodeInfo, ...]:
        """Nodes in other processes that this transport has discovered."""
        return ()

    def __repr__(self) -> str:
        return f"<{type(self).__name__} domain_id={self.domain_id}>"


class LocalTransport(Transport):
    """One process, no network: the bus alone."""

    name = "local"


def make_transport(name: str, *, domain_id: int = 0, **options: Any) -> Transport:
    """``"local"`` or ``"zenoh"``; ``options`` go to the zenoh transport (``config_file``, ``connect``, ``listen``).

    For zenoh, ``ROS_DOMAIN_ID`` in the environment applies when ``domain_id`` is left at 0,
    as in ROS 2.
    """
    if name == "local":
        return LocalTransport(domain_id=domain_id)
    if name == "zenoh":
        from ..transport import ZenohTransport

        if domain_id == 0 and os.environ.get("ROS_DOMAIN_ID", "").strip():
            raw = os.environ["ROS_DOMAIN_ID"].strip()
            if not raw.isdigit() or not 0 <= int(raw) <= 232:
                raise ValueError(f"ROS_DOMAIN_ID: expected an int in 0..232, found {raw!r}")
            domain_id = int(raw)
        return ZenohTransport(domain_id=domain_id, **options)
    raise ValueError(f"transport: expected 'local' or 'zenoh', found {name!r}")
