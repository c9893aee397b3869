"""``FoxgloveBridge``: a Foxglove WebSocket server (foxglove-sdk) showing a running graph live.

Every topic becomes a channel with its ``ros2msg`` schema and CDR messages, so Foxglove's ROS
panels (3D with ``/tf`` and ``/tf_static``, Image, Plot, Raw Messages) work as they do with a
ROS 2 bridge. Node parameters appear under ``/<node>.<name>`` and services can be called from
the app.

The control loop must never wait on a viewer: a topic costs its publisher one check while no
client is subscribed, and otherwise one append to a bounded queue; a bridge thread serialises
and sends. Large messages (images, clouds) are throttled to ``max_large_hz`` per topic and the
queue drops its oldest entry when a slow client lets it fill.
"""

from __future__ import annotations

import asyncio
import threading

from collections import deque
from dataclasses import dataclass
from typing import Any

from .._core._node import Node
from .._core._pubsub import Endpoint, Publisher
from ..lowlevel import Tap, add_tap, node_loop, remove_tap, watch_publishers
from .._core._qos import QoSProfile, ReliabilityPolicy

__all__ = ["FoxgloveBridge", "FoxgloveStatistics"]

#: Serialised size above which a message counts as large (throttled by ``max_large_hz``).
LARGE_BYTES = 64 * 1024
_LARGE_TYPES = frozenset(
    {"sensor_msgs/msg/Image", "sensor_msgs/msg/CompressedImage", "sensor_msgs/msg/PointCloud2", "nav_msgs/msg/OccupancyGrid"}
)


@dataclass(frozen=True, slots=True)
class FoxgloveStatistics:
    """Channels advertised, messages sent to clients, dropped by throttling or a full queue."""

    channels: int
    sent: int
    throttled: int
    dropped: int
    port: int


class FoxgloveBridge(Node):
    """A node serving the graph to Foxglove over WebSocket.

    Parameters: ``host`` (default 127.0.0.1), ``port`` (default 8765; 0 picks a free port),
    ``max_large_hz`` (per-topic rate limit for images/clouds, default 10), ``queue`` (messages
    waiting for the bridge thread before the oldest is dropped, default 256).
    """

    def __init__(self, node_name: str = "foxglove_bridge", *, host: str = "127.0.0.1", port: int = 8765,
                 max_large_hz: float = 10.0, queue: int = 256, **kwargs: Any) -> None:
        super().__init__(node_name, **kwargs)
        self.host = str(self.declare_parameter("host", host).value)
        self.port = int(self.declare_parameter("port", int(port)).value)
        self.max_large_hz = float(self.declare_parameter("max_large_hz", float(max_large_hz)).value)
        self.queue_size = int(self.declare_parameter("queue", int(queue)).value)
        if not 0 <= self.port <= 65535:
            raise ValueError(f"foxglove bridge: port must be 0..65535, found {self.port}")
        if not self.max_large_hz > 0 or self.queue_size < 1:
            raise ValueError("foxglove bridge: max_large_hz must be > 0 and queue >= 1")
        self._lock = threading.Lock()
        self._channels: dict[str, Any] = {}
        self._taps: list[Tap] = []
        self._pending: deque[tuple[Any, Any, int]] = deque(maxlen=self.queue_size)
        self._wake = threading.Event()
        self._halt = threading.Event()
        self._thread: threading.Thread | None = None
        self._server: Any = None
        self._context: Any = None
        self._unwatch: Any = None
        self._sent = self._throttled = self._dropped = 0
        self._services_added: set[str] = set()

    def __repr__(self) -> str:
        return f"<FoxgloveBridge ws://{self.host}:{self.bound_port} channels={len(self._channels)}>"

    @property
    def bound_port(self) -> int:
        return int(self._server.port) if self._server is not None else self.port

    def statistics(self) -> FoxgloveStatistics:
        return FoxgloveStatistics(len(self._channels), self._sent, self._throttled, self._dropped, self.bound_port)

    # -- lifecycle ----------------------------------------------------------------------

    def on_added(self) -> None:
        # attach at once, as the Recorder does: a publisher added next must not publish unseen
        if self._server is None:
            self._attach()

    def _attach(self) -> None:
        import foxglove
        from foxglove.websocket import Capability

        self._context = foxglove.Context()
        try:
            self._server = foxglove.start_server(
                name=f"aiorobot {self.get_fully_qualified_name()}",
                host=self.host,
                port=self.port,
                capabilities=[Capability.Parameters, Capability.Services],
                server_listener=_Listener(self),
                supported_encodings=["cdr"],
                context=self._context,
            )
        except Exception as err:  # port taken, bad host: one line, nothing half-started
            raise OSError(f"foxglove bridge: cannot listen on {self.host}:{self.port} ({err})") from None
        self._thread = threading.Thread(target=self._send_loop, name="aiorobot-foxglove", daemon=True)
        self._thread.start()
        self._unwatch = watch_publishers(self.runtime, self._on_endpoint)

    async def on_start(self) -> None:
        self._refresh_services()
        self.get_logger().info(f"Foxglove: open ws://{self.host}:{self.bound_port} in the Foxglove app")

    async def on_shutdown(self) -> None:
        self.close()

    def close(self) -> None:
        """Stop serving: detach from the bus, stop the thread and the server. Idempotent."""
        if self._unwatch is not None:
            self._unwatch()
            self._unwatch = None
        if self.executor is not None:
            for tap in self._taps:
                remove_tap(self.runtime, tap)
        self._taps.clear()
        self._halt.set()
        self._wake.set()
        if self._thread is not None:
            self._thread.join(timeout=2.0)
            self._thread = None
        if self._server is not None:
            self._server.stop()
            self._server = None
        for channel in self._channels.values():
            channel.close()
        self._channels.clear()

    # -- topics -------------------------------------------------------------------------

    def _on_endpoint(self, endpoint: Endpoint) -> None:
        if not isinstance(endpoint, Publisher):
            return
        import foxglove
        from aiorobot.msgs import message_definition

        name = endpoint.topic_name
        with self._lock:
            if name in self._channels or self._server is None:
                return
            type_name = str(endpoint.msg_type.__msgtype__)
            channel = foxglove.Channel(
                name,
                schema=foxglove.Schema(name=type_name, encoding="ros2msg", data=message_definition(type_name).encode()),
                message_encoding="cdr",
                context=self._context,
            )
            self._channels[name] = channel
            large = type_name in _LARGE_TYPES
            period_ns = int(1e9 / self.max_large_hz)
            last = [0]
            pending = self._pending
            wake = self._wake
            clock = self.runtime.clock

            def forward(msg: Any) -> None:
                if not channel.has_sinks():
                    return  # nobody watches this topic: cost one check
                now = clock.now().nanoseconds
                if large:
                    if now - last[0] < period_ns:
                        self._throttled += 1
                        return
                    last[0] = now
                if len(pending) == pending.maxlen:
                    self._dropped += 1
                pending.append((channel, msg, now))
                wake.set()

            qos = QoSProfile(reliability=ReliabilityPolicy.BEST_EFFORT, durability=endpoint.qos.durability, depth=max(1, endpoint.qos.depth))
            tap = Tap(endpoint.msg_type, name, qos, forward, owner=self.get_fully_qualified_name())
            tap.node, tap.wants_remote = self, True  # also receives remote publishers over a transport
            self._taps.append(tap)
        add_tap(self.runtime, tap)

    def _send_loop(self) -> None:
        from aiorobot.msgs import serialize

        while not self._halt.is_set():
            self._wake.wait(0.5)
            self._wake.clear()
            while self._pending:
                try:
                    channel, msg, t_ns = self._pending.popleft()
                except IndexError:
                    break
                try:
                    channel.log(serialize(msg), log_time=t_ns)
                    self._sent += 1
                except Exception as err:  # a closed channel during shutdown, a message that does not serialise
                    self.get_logger().warning(f"foxglove: cannot send on {channel.topic} ({err})", throttle_duration_sec=5.0)

    # -- parameters and services ----------------------------------------------------------

    def _nodes(self) -> list[Node]:
        return list(self.runtime.nodes) if self.executor is not None else []

    def _get_parameters(self, names: list[str]) -> list[Any]:
        from foxglove.websocket import Parameter

        out = []
        for node in self._nodes():
            prefix = node.get_fully_qualified_name()
            for pname in node.list_parameters().names:
                full = f"{prefix}.{pname}"
                if names and full not in names:
                    continue
                value = node.get_parameter(pname).value
                out.append(Parameter(full, value=_to_foxglove(value)))
        return out

    def _set_parameters(self, params: list[Any]) -> list[Any]:
        from aiorobot import Parameter as AParameter

        by_node = {n.get_fully_qualified_name(): n for n in self._nodes()}
        for p in params:
            node_name, _, pname = p.name.rpartition(".")
            node = by_node.get(node_name)
            if node is None:
                continue
            value = _from_foxglove(p.get_value())
            fut = asyncio.run_coroutine_threadsafe(_set(node, AParameter(pname, value)), node_loop(node))  # type: ignore[arg-type]
            try:
                fut.result(timeout=5.0)
            except Exception as err:
                self.get_logger().warning(f"foxglove: setting {p.name} failed ({err})")
        return self._get_parameters([p.name for p in params])

    def _refresh_services(self) -> None:
        """Offer every service of the graph to the app (request/response as ros2msg + CDR)."""
        from foxglove.websocket import MessageSchema, Service, ServiceSchema

        import foxglove
        from aiorobot.msgs import get, message_definition

        if self._server is None:
            return
        new = []
        for name, type_name in self._service_names():
            if name in self._services_added:
                continue
            srv = get(type_name)

            def schema(t: Any) -> Any:
                tn = str(t.__msgtype__)
                return MessageSchema(encoding="cdr", schema=foxglove.Schema(name=tn, encoding="ros2msg", data=message_definition(tn).encode()))

            handler = _ServiceHandler(self, name, srv)
            new.append(Service(name, schema=ServiceSchema(type_name, request=schema(srv.Request), response=schema(srv.Response)), handler=handler))
            self._services_added.add(name)
        if new:
            self._server.add_services(new)

    def _service_names(self) -> list[tuple[str, str]]:
        graph = self.runtime.graph
        out = []
        for svc in graph.services:
            if svc.servers and svc.types:
                out.append((svc.name, svc.types[0]))
        return out


async def _set(node: Node, param: Any) -> None:
    results = node.set_parameters([param])
    if results and not results[0].successful:
        raise ValueError(results[0].reason)


class _ServiceHandler:
    """Calls a graph service for the app: CDR request in, CDR response out (in the server's thread)."""

    def __init__(self, bridge: FoxgloveBridge, name: str, srv: Any) -> None:
        self.bridge = bridge
        self.name = name
        self.srv = srv
        self.client: Any = None

    def __call__(self, request: Any) -> bytes:
        from aiorobot.msgs import deserialize, serialize

        req = deserialize(bytes(request.payload), self.srv.Request)
        loop = node_loop(self.bridge)
        assert loop is not None

        async def call() -> Any:
            if self.client is None:
                self.client = self.bridge.create_client(self.srv, self.name)
            return await self.client.call(req, timeout_sec=10.0)

        response = asyncio.run_coroutine_threadsafe(call(), loop).result(timeout=15.0)
        return serialize(response)


def _Listener(bridge: FoxgloveBridge) -> Any:  # noqa: N802 - builds the listener class lazily (foxglove import)
    from foxglove.websocket import ServerListener

    class Listener(_ParameterListener, ServerListener):
        pass

    return Listener(bridge)


class _ParameterListener:
    """foxglove-sdk's ServerListener for parameters (names ``/<node>.<parameter>``)."""

    def __init__(self, bridge: FoxgloveBridge) -> None:
        self.bridge = bridge

    def on_get_parameters(self, client: Any, param_names: list[str], request_id: str | None = None) -> list[Any]:
        return self.bridge._get_parameters(list(param_names))

    def on_set_parameters(self, client: Any, parameters: list[Any], request_id: str | None = None) -> list[Any]:
        return self.bridge._set_parameters(list(parameters))


def _to_foxglove(value: Any) -> Any:
    from foxglove.websocket import ParameterValue

    if isinstance(value, bool):
        return ParameterValue.Bool(value)
    if isinstance(value, int):
        return ParameterValue.Integer(value)
    if isinstance(value, float):
        return ParameterValue.Float64(value)
    if isinstance(value, str):
        return ParameterValue.String(value)
    if isinstance(value, (list, tuple)):
        return ParameterValue.Array([_to_foxglove(v) for v in value])
    return ParameterValue.String(repr(value))


def _from_foxglove(value: Any) -> Any:
    if isinstance(value, list):
        return [_from_foxglove(v) for v in value]
    return value


