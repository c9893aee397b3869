"""The graph as the Foxglove app sees it beyond topics: services and the connection graph, kept
current while nodes (in this process or others) come and go.

Topics need no polling (the bridge learns of every publisher, remote ones included, as it joins);
services and the connection graph are read from ``Runtime.graph`` every ``period_sec`` on the
bridge node's loop (wall time: a paused sim clock must not freeze the view), and only a change
is sent.
"""

from __future__ import annotations

import asyncio
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from ._bridge import FoxgloveBridge

__all__ = ["GraphView"]


class GraphView:
    """Offers the graph's services to the app and publishes its connection graph."""

    def __init__(self, bridge: FoxgloveBridge, *, period_sec: float = 0.5) -> None:
        self.bridge = bridge
        self.period_sec = period_sec
        self._services: dict[str, str] = {}  # offered: name -> type
        self._connections: Any = None

    async def run(self) -> None:
        while True:
            try:
                self.refresh()
            except Exception as err:  # noqa: BLE001 - one bad refresh must not end the watch; say so
                self.bridge.get_logger().warning(f"foxglove: graph refresh failed ({type(err).__name__}: {err})",
                                                 throttle_duration_sec=10.0)
            await asyncio.sleep(self.period_sec)

    def refresh(self) -> None:
        server = self.bridge.server
        if server is None:
            return
        graph = self.bridge.runtime.graph
        self._refresh_services(server, graph)
        self._refresh_connections(server, graph)

    def _refresh_services(self, server: Any, graph: Any) -> None:
        now = {s.name: s.types[0] for s in graph.services if s.servers and s.types}
        gone = [name for name, type_name in self._services.items() if now.get(name) != type_name]
        if gone:
            server.remove_services(gone)
            for name in gone:
                del self._services[name]
        new = []
        for name, type_name in sorted(now.items()):
            if name in self._services:
                continue
            service = self._service(name, type_name)
            if service is not None:
                new.append(service)
                self._services[name] = type_name
        if new:
            server.add_services(new)

    def _service(self, name: str, type_name: str) -> Any:
        import foxglove
        from foxglove.websocket import MessageSchema, Service, ServiceSchema

        from aiorobot.msgs import get, message_definition

        try:
            srv = get(type_name)
        except Exception:  # noqa: BLE001 - a type this process does not know: it cannot encode calls
            self.bridge.get_logger().warning(f"foxglove: service {name} not offered: unknown type {type_name}")
            return None

        def schema(t: Any) -> Any:
            tn = str(t.__msgtype__)
            return MessageSchema(encoding="cdr", schema=foxglove.Schema(name=tn, encoding="ros2msg", data=message_definition(tn).encode()))

        return Service(name, schema=ServiceSchema(type_name, request=schema(srv.Request), response=schema(srv.Response)),
                       handler=_ServiceHandler(self.bridge, name, srv))

    def _refresh_connections(self, server: Any, graph: Any) -> None:
        from foxglove import ConnectionGraph

        me = self.bridge.get_fully_qualified_name()
        published = {t.name: sorted({e.node for e in t.publishers if e.node != me}) for t in graph.topics}
        subscribed = {t.name: sorted({e.node for e in t.subscriptions if e.node != me}) for t in graph.topics}
        services = {s.name: sorted(set(s.servers)) for s in graph.services if s.servers}
        key = (published, subscribed, services)
        if key == self._connections:
            return
        self._connections = key
        cg = ConnectionGraph()
        for topic, ids in published.items():
            if ids:
                cg.set_published_topic(topic, ids)
        for topic, ids in subscribed.items():
            if ids:
                cg.set_subscribed_topic(topic, ids)
        for service, ids in services.items():
            cg.set_advertised_service(service, ids)
        server.publish_connection_graph(cg)


class _ServiceHandler:
    """Calls a graph service for the app: CDR request in, CDR response out (in the server's thread)."""

    def __init__(self, bridge: FoxgloveBridge, name: str, srv: Any) -> None:
        self.bridge = bridge
        self.name = name
        self.srv = srv
        self.client: Any = None

    def __call__(self, request: Any) -> bytes:
        from aiorobot.lowlevel import node_loop
        from aiorobot.msgs import deserialize, serialize

        req = deserialize(bytes(request.payload), self.srv.Request)
        loop = node_loop(self.bridge)
        if loop is None:
            raise RuntimeError(f"foxglove bridge stopped: cannot call {self.name}")

        async def call() -> Any:
            if self.client is None:
                self.client = self.bridge.create_client(self.srv, self.name)
            return await asyncio.wait_for(self.client.call(req), 10.0)

        response = asyncio.run_coroutine_threadsafe(call(), loop).result(timeout=15.0)
        return serialize(response)
