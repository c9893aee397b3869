"""``FoxgloveBridge``: a Foxglove WebSocket server (foxglove-sdk) showing a running graph live and
taking commands from it.

Every topic becomes a channel with its ``ros2msg`` schema and CDR messages, so Foxglove's ROS
panels (3D with ``/tf`` and ``/tf_static``, Image, Plot, Raw Messages) work as they do with a
ROS 2 bridge. The server's capabilities, each in its own module:

- ``clientPublish`` (:mod:`._client_publish`): the teleop panel's Twist, "Publish pose" on
  ``/goal_pose`` and "Publish pose estimate" on ``/initialpose`` reach the graph;
- ``parameters`` and ``parametersSubscribe`` of every node, in any process (:mod:`._parameters`);
- ``services`` and ``connectionGraph``, kept current as nodes come and go (:mod:`._graph_view`);
- ``assets``: ``package://`` and ``file://`` under the configured roots (:mod:`._assets`);
- ``time``: on sim time, the latest ``/clock`` at 10 Hz or more;
- ``playbackControl`` when serving a :class:`~aiorobot.bag.Player` (:mod:`._playback`).

A topic published transient local (``/robot_description``, ``/map``, ``/tf_static``) keeps its
last messages, and a client that subscribes later gets them, to it alone, as a late-joining ROS
subscriber would; each of its messages reaches each client once, also when one is published as
the client subscribes (such a topic is sent client by client, not broadcast).

The control loop must never wait on a viewer: a topic costs its publisher one check while no
client is subscribed, and otherwise one append to a bounded queue; a bridge thread serialises
and sends. Large messages (images, clouds) are throttled to ``max_large_hz`` per topic and the
queue drops its oldest entry when a slow client lets it fill.
"""

from __future__ import annotations

import itertools
import threading
import time
from collections import deque
from dataclasses import dataclass
from typing import Any

from .._core._node import Node
from .._core._pubsub import Publisher
from .._core._qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from ..lowlevel import Tap, add_tap, remove_tap, watch_publishers
from ._assets import AssetResolver
from ._client_publish import ClientPublishing
from ._graph_view import GraphView
from ._parameters import GraphParameters

__all__ = ["FoxgloveBridge", "FoxgloveStatistics"]

#: Serialised size above which a message counts as large (throttled by ``max_large_hz``).
LARGE_BYTES = 64 * 1024
_LARGE_TYPES = frozenset(
    {"sensor_msgs/msg/Image", "sensor_msgs/msg/CompressedImage", "sensor_msgs/msg/PointCloud2", "nav_msgs/msg/OccupancyGrid"}
)
#: transient-local messages kept per topic for late clients (robot_description, map, tf_static)
_LATCHED_DEPTH = 16
#: on sim time, the time is sent again after this long without a new /clock (10 Hz at least)
_TIME_REPEAT_NS = 100_000_000


class _Latched:
    """A transient-local topic's kept messages, numbered, and the last one each subscribed client got.

    Its messages go to each subscribed client by itself, never broadcast, and all sending happens
    on the bridge's send thread: a client that subscribes while a message is on its way gets it
    once, replayed or live, whichever comes first (broadcast, it got it live as well as replayed
    when the server had counted the subscription before the message and told the bridge after)."""

    def __init__(self, depth: int) -> None:
        self.kept: deque[tuple[int, Any, int]] = deque(maxlen=depth)
        self._seq = itertools.count()
        self._got: dict[int, int] = {}  # client id -> the last number it got (send thread only)

    def keep(self, msg: Any, t_ns: int) -> int:
        """On a publishing thread: keep ``msg``; its number."""
        seq = next(self._seq)
        self.kept.append((seq, msg, t_ns))
        return seq

    def subscribe(self, client: int) -> list[tuple[int, Any, int]]:
        """What ``client``, subscribing, has not got of the kept messages, in order."""
        got = self._got.get(client, -1)
        missing = [entry for entry in list(self.kept) if entry[0] > got]
        self._got[client] = missing[-1][0] if missing else got
        return missing

    def live(self, seq: int) -> list[int]:
        """The subscribed clients that have not got message ``seq`` yet (now counted as having it)."""
        clients = [client for client, got in self._got.items() if got < seq]
        for client in clients:
            self._got[client] = seq
        return clients

    def unsubscribe(self, client: int) -> None:
        self._got.pop(client, None)


@dataclass(frozen=True, slots=True)
class FoxgloveStatistics:
    """Channels advertised, messages sent to clients, dropped by throttling or a full queue;
    messages clients published into the graph and refused (unknown topic, bad schema or data)."""

    channels: int
    sent: int
    throttled: int
    dropped: int
    port: int
    client_published: int = 0
    client_refused: int = 0


class FoxgloveBridge(Node):
    """A node serving the graph to Foxglove over WebSocket.

    Parameters: ``host`` (default 127.0.0.1), ``port`` (default 8765; 0 picks a free port),
    ``max_large_hz`` (per-topic rate limit for images/clouds, default 10), ``queue`` (messages
    waiting for the bridge thread before the oldest is dropped, default 256), ``asset_roots``
    (folders ``package://`` and ``file://`` URIs may read from, besides the packages' share
    folders). ``player``: a :class:`~aiorobot.bag.Player` whose playback the app controls.
    """

    def __init__(self, node_name: str = "foxglove_bridge", *, host: str = "127.0.0.1", port: int = 8765,
                 max_large_hz: float = 10.0, queue: int = 256, asset_roots: list[str] | None = None,
                 player: Any = None, **kwargs: Any) -> None:
        super().__init__(node_name, **kwargs)
        self.host = str(self.declare_parameter("host", host).value)
        self.port = int(self.declare_parameter("port", int(port)).value)
        self.max_large_hz = float(self.declare_parameter("max_large_hz", float(max_large_hz)).value)
        self.queue_size = int(self.declare_parameter("queue", int(queue)).value)
        roots = [r for r in self.declare_parameter("asset_roots", list(asset_roots or [""])).value if r]
        if not 0 <= self.port <= 65535:
            raise ValueError(f"foxglove bridge: port must be 0..65535, found {self.port}")
        if not self.max_large_hz > 0 or self.queue_size < 1:
            raise ValueError("foxglove bridge: max_large_hz must be > 0 and queue >= 1")
        self.assets = AssetResolver(roots)  # a root that is not a folder fails here
        self.player = player
        self._lock = threading.Lock()
        self._channels: dict[str, Any] = {}
        self._latched: dict[str, _Latched] = {}
        #: clients subscribing to and leaving transient-local topics, for the send thread
        self._latched_events: deque[tuple[bool, int, str]] = deque()
        self._taps: list[Tap] = []
        self._client_pubs: dict[str, Any] = {}
        #: (channel, message, time, to: None for all, a client id, or a _Latched topic's clients, its number)
        self._pending: deque[tuple[Any, Any, int, Any, int]] = deque(maxlen=self.queue_size)
        self._wake = threading.Event()
        self._halt = threading.Event()
        self._thread: threading.Thread | None = None
        self._server: Any = None
        self._context: Any = None
        self._unwatch: Any = None
        self._sent = self._throttled = self._dropped = 0
        self._sim_time = False
        self._clock_ns: int | None = None
        self._told_clock = False
        self.client_publishing = ClientPublishing(self)
        self.parameters = GraphParameters(self)
        self.graph_view = GraphView(self)
        self.playback: Any = None

    def __repr__(self) -> str:
        return f"<FoxgloveBridge ws://{self.host}:{self.bound_port} channels={len(self._channels)}>"

    @property
    def bound_port(self) -> int:
        return int(self._server.port) if self._server is not None else self.port

    @property
    def server(self) -> Any:
        """foxglove-sdk's ``WebSocketServer`` while serving, else None."""
        return self._server

    def statistics(self) -> FoxgloveStatistics:
        cp = self.client_publishing
        return FoxgloveStatistics(len(self._channels), self._sent, self._throttled, self._dropped, self.bound_port,
                                  cp.published, cp.refused)

    # -- lifecycle ----------------------------------------------------------------------

    def on_added(self) -> None:
        # attach at once, as the Recorder does: a publisher added next must not publish unseen
        if self._server is None:
            self._attach()

    def _attach(self) -> None:
        import foxglove
        from foxglove.websocket import Capability

        from ._listener import make_listener

        self._sim_time = bool(self.runtime.use_sim_time or self.get_parameter("use_sim_time").value)
        capabilities = [Capability.ClientPublish, Capability.Parameters, Capability.Services, Capability.ConnectionGraph]
        if self._sim_time:
            capabilities.append(Capability.Time)
        time_range = None
        if self.player is not None:
            from ._playback import PlaybackControl

            self.playback = PlaybackControl(self, self.player)
            time_range = self.playback.time_range
        self._context = foxglove.Context()
        try:
            self._server = foxglove.start_server(
                name=f"aiorobot {self.get_fully_qualified_name()}",
                host=self.host,
                port=self.port,
                capabilities=capabilities,
                server_listener=make_listener(self),
                supported_encodings=["cdr"],
                asset_handler=self.assets,
                context=self._context,
                playback_time_range=time_range,
            )
        except Exception as err:  # port taken, bad host: one line, nothing half-started
            raise OSError(f"foxglove bridge: cannot listen on {self.host}:{self.port} ({err})") from None
        self._thread = threading.Thread(target=self._send_loop, name="aiorobot-foxglove", daemon=True)
        self._thread.start()
        if self._sim_time:
            self._tap_clock()
        self.parameters.start()
        self._unwatch = watch_publishers(self.runtime, self._on_endpoint)

    async def on_start(self) -> None:
        self.graph_view.refresh()
        self.create_task(self.graph_view.run(), name="aiorobot-foxglove graph")
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

    # -- what the capabilities call -------------------------------------------------------

    def error_status(self, message: str, status_id: str) -> None:
        """Tell the app (an error status) and the log."""
        from foxglove.websocket import StatusLevel

        self.get_logger().warning(message)
        if self._server is not None:
            self._server.publish_status(message, StatusLevel.Error, status_id)

    def remove_status(self, status_id: str) -> None:
        if self._server is not None:
            self._server.remove_status([status_id])

    def publisher_for(self, msg_type: Any, topic: str) -> Any:
        """The bridge's publisher on ``topic`` (one per topic, made on first use; call on the node's loop)."""
        pub = self._client_pubs.get(topic)
        if pub is None or pub.msg_type is not msg_type:
            pub = self._client_pubs[topic] = self.create_publisher(msg_type, topic, 10)
        return pub

    def replay_latched(self, client_id: int, topic: str) -> None:
        """A client subscribed to ``topic``: if it is transient local, the send thread sends it the
        kept messages it has not got, and from then on each new one."""
        if topic in self._latched:
            self._latched_events.append((True, client_id, topic))
            self._wake.set()

    def forget_latched(self, client_id: int, topic: str) -> None:
        """A client unsubscribed from ``topic`` (or left): a new subscription gets the kept messages again."""
        if topic in self._latched:
            self._latched_events.append((False, client_id, topic))
            self._wake.set()

    # -- topics -------------------------------------------------------------------------

    def _on_endpoint(self, endpoint: Publisher[Any]) -> None:
        import foxglove
        from aiorobot.msgs import message_definition

        name = endpoint.topic_name
        if name == "/clock" and not self._sim_time and not self._told_clock:
            self._told_clock = True
            self.get_logger().info("the graph publishes /clock but this bridge runs on wall time: start it on sim time "
                                   "(use_sim_time, `aiorobot foxglove --use-sim-time`) for Foxglove to follow /clock")
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
            latched: _Latched | None = None
            if endpoint.qos.durability == DurabilityPolicy.TRANSIENT_LOCAL:
                latched = self._latched[name] = _Latched(max(1, min(endpoint.qos.depth, _LATCHED_DEPTH)))

            def forward(msg: Any) -> None:
                seq = latched.keep(msg, clock.now().nanoseconds) if latched is not None else 0
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
                pending.append((channel, msg, now, latched, seq))
                wake.set()

            qos = QoSProfile(reliability=ReliabilityPolicy.BEST_EFFORT, durability=endpoint.qos.durability, depth=max(1, endpoint.qos.depth))
            tap = Tap(endpoint.msg_type, name, qos, forward, owner=self.get_fully_qualified_name())
            tap.node, tap.wants_remote = self, True  # also receives remote publishers over a transport
            self._taps.append(tap)
        add_tap(self.runtime, tap)

    def _tap_clock(self) -> None:
        from aiorobot.msgs.rosgraph_msgs import Clock

        def on_clock(msg: Any) -> None:
            self._clock_ns = int(msg.clock.sec) * 1_000_000_000 + int(msg.clock.nanosec)
            self._wake.set()

        tap = Tap(Clock, "/clock", QoSProfile(reliability=ReliabilityPolicy.BEST_EFFORT, depth=1), on_clock,
                  owner=self.get_fully_qualified_name())
        tap.node, tap.wants_remote = self, True
        self._taps.append(tap)
        add_tap(self.runtime, tap)

    def _send(self, channel: Any, msg: Any, t_ns: int, client: int | None) -> None:
        """On the send thread: log ``msg`` on ``channel``, to one client or (None) to every subscriber."""
        from aiorobot.msgs import serialize

        try:
            channel.log(serialize(msg), log_time=t_ns, sink_id=client)
            self._sent += 1
        except Exception as err:  # a closed channel during shutdown, a message that does not serialise
            self.get_logger().warning(f"foxglove: cannot send on {channel.topic} ({err})", throttle_duration_sec=5.0)

    def _send_loop(self) -> None:
        sent_clock: int | None = None
        sent_clock_at = 0
        period = 0.05 if (self._sim_time or self.playback is not None) else 0.5
        while not self._halt.is_set():
            self._wake.wait(period)
            self._wake.clear()
            while self._latched_events:
                subscribed, client, topic = self._latched_events.popleft()
                latched, channel = self._latched.get(topic), self._channels.get(topic)
                if latched is None or channel is None:
                    continue
                if not subscribed:
                    latched.unsubscribe(client)
                    continue
                for _, msg, t_ns in latched.subscribe(client):
                    self._send(channel, msg, t_ns, client)
            while self._pending:
                try:
                    channel, msg, t_ns, to, seq = self._pending.popleft()
                except IndexError:
                    break
                if isinstance(to, _Latched):
                    for client in to.live(seq):
                        self._send(channel, msg, t_ns, client)
                else:
                    self._send(channel, msg, t_ns, to)
            server = self._server
            if server is None:
                continue
            now = time.monotonic_ns()
            clock_ns = self._clock_ns
            if clock_ns is not None and (clock_ns != sent_clock or now - sent_clock_at >= _TIME_REPEAT_NS):
                server.broadcast_time(clock_ns)
                sent_clock, sent_clock_at = clock_ns, now
            if self.playback is not None:
                self.playback.tick(server)
