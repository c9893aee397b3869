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
plugs in without changing it. Transports are found by name in a registry
(:func:`register_transport`): the core registers ``"local"``, and importing
``aiorobot.transport`` registers ``"zenoh"``; the core never imports an implementation.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from ._bus import Bus, Endpoint
    from ._graph import NodeInfo
    from ._node import Node

__all__ = ["MAX_DOMAIN_ID", "LocalTransport", "Transport", "make_transport", "register_transport", "transport_names"]

#: The largest ROS domain id (``ROS_DOMAIN_ID``, ``Runtime(domain_id=)``, ``[runtime] domain_id``).
MAX_DOMAIN_ID = 232


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


#: Transport name -> factory called as ``factory(domain_id=..., **options)``. The core registers
#: only ``"local"``; a package that provides transports registers them when it is imported.
_REGISTRY: dict[str, Callable[..., Transport]] = {}
#: Packages imported, once, the first time a name is not registered: the built-in transports
#: (``aiorobot.transport`` registers ``"zenoh"``). The core names the package, never an implementation.
_PROVIDERS = ("aiorobot.transport",)
_providers_loaded = False


def register_transport(name: str, factory: Callable[..., Transport]) -> None:
    """Make ``name`` usable as ``Runtime(transport=name)``, ``transport = name`` in a config file and ``--transport``.

    ``factory(domain_id=..., **options)`` returns a new, unopened :class:`Transport`.
    Registering a name twice with a different factory raises ``ValueError``.
    """
    if not isinstance(name, str) or not name.isidentifier():
        raise ValueError(f"transport name: expected an identifier such as 'zenoh', found {name!r}")
    if not callable(factory):
        raise TypeError(f"transport {name!r}: expected a factory (a Transport subclass or function), found {factory!r}")
    known = _REGISTRY.get(name)
    if known is not None and known is not factory:
        raise ValueError(f"transport {name!r} is already registered to {known!r}; pick another name")
    _REGISTRY[name] = factory


def transport_names() -> tuple[str, ...]:
    """The names :func:`make_transport` accepts, the built-in transports' included."""
    _load_providers()
    return tuple(sorted(_REGISTRY))


def _load_providers() -> None:
    global _providers_loaded
    if not _providers_loaded:
        for package in _PROVIDERS:
            importlib.import_module(package)
        _providers_loaded = True


def make_transport(name: str, *, domain_id: int = 0, **options: Any) -> Transport:
    """A new transport by its registered name: ``"local"``, ``"zenoh"`` or one a package registered.

    ``options`` go to the transport's factory (zenoh takes ``config_file``, ``connect``, ``listen``).
    """
    factory = _REGISTRY.get(name)
    if factory is None:
        _load_providers()
        factory = _REGISTRY.get(name)
    if factory is None:
        names = ", ".join(repr(n) for n in sorted(_REGISTRY))
        raise ValueError(f"transport: expected one of {names}, found {name!r}")
    return factory(domain_id=domain_id, **options)


register_transport("local", LocalTransport)
