"""clientPublish: what a Foxglove client publishes (teleop Twist, "Publish pose") reaches the graph.

A client advertises a channel (topic, encoding, schema name), then sends CDR messages on it. The
channel becomes a publisher of the bridge node on that topic once three checks pass: the encoding
is ``cdr``, some node of the graph (in any process) publishes or subscribes the topic, and the
advertised schema is the topic's type. A check that fails is reported as an error status naming
the client, the topic, what was expected and what was found, and nothing is published; a topic
that appears later is checked again at the next message. A message that does not decode as the
topic's type is refused the same way.

Threads: the server calls in from its own thread; every step after the advertisement's record is
posted to the bridge node's loop in arrival order, so a teleop stream keeps its order and loses
nothing (the publisher's own QoS decides what a slow subscriber drops, as for any publisher).

foxglove-sdk 0.30's Python API sends a status to every client (``publish_status``), not to one:
the status says which client it concerns (``client N``) and carries an id per client channel.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from .._core._handoff import post
from ..lowlevel import node_loop

if TYPE_CHECKING:
    from ._bridge import FoxgloveBridge

__all__ = ["ClientPublishing"]

#: a refused channel repeats its error status at most this often (a 20 Hz teleop stream would flood)
_REPEAT_SEC = 1.0


@dataclass(slots=True)
class _ClientChannel:
    client: int
    id: int
    topic: str
    encoding: str
    schema_name: str
    msg_type: Any = None
    publisher: Any = None
    last_error: float = field(default=-1e9)


def ros2_type_name(schema_name: str) -> str:
    """``geometry_msgs/Twist`` and ``geometry_msgs/msg/Twist`` both name ``geometry_msgs/msg/Twist``."""
    parts = schema_name.split("/")
    if len(parts) == 2 and all(parts):
        return f"{parts[0]}/msg/{parts[1]}"
    return schema_name


class ClientPublishing:
    """The client channels of one bridge and the publishers they feed."""

    def __init__(self, bridge: FoxgloveBridge) -> None:
        self.bridge = bridge
        self._channels: dict[tuple[int, int], _ClientChannel] = {}
        self.published = 0
        self.refused = 0

    # -- from the server's thread ----------------------------------------------------------

    def on_advertise(self, client: Any, channel: Any) -> None:
        ch = _ClientChannel(int(client.id), int(channel.id), str(channel.topic), str(channel.encoding), str(channel.schema_name or ""))
        self._channels[(ch.client, ch.id)] = ch
        self._to_loop(self._open, ch)

    def on_unadvertise(self, client: Any, channel_id: int) -> None:
        self._channels.pop((int(client.id), int(channel_id)), None)

    def on_message(self, client: Any, channel_id: int, data: bytes) -> None:
        ch = self._channels.get((int(client.id), int(channel_id)))
        if ch is not None:  # an unknown id: the server has told the client already
            self._to_loop(self._deliver, ch, bytes(data))

    def _to_loop(self, fn: Any, *args: Any) -> None:
        loop = node_loop(self.bridge)
        if loop is not None:
            post(loop, fn, *args)

    # -- on the bridge node's loop ---------------------------------------------------------

    def _open(self, ch: _ClientChannel) -> str | None:
        """Check ``ch`` against the graph and give it a publisher; the reason it cannot have one."""
        from aiorobot.msgs import get

        if ch.publisher is not None:
            return None
        if ch.encoding != "cdr":
            return self._refuse(ch, f"expected message encoding 'cdr', found {ch.encoding!r}")
        type_name = ros2_type_name(ch.schema_name)
        others = [e for e in self._endpoints(ch.topic) if e.node != self.bridge.get_fully_qualified_name()]
        if not others:
            return self._refuse(ch, "unknown topic: no node of the graph publishes or subscribes it")
        types = sorted({e.type for e in others})
        if type_name not in types:
            return self._refuse(ch, f"bad schema: the topic carries {' | '.join(types)}, the client advertised {ch.schema_name!r}")
        try:
            ch.msg_type = get(type_name)
        except Exception as err:  # noqa: BLE001 - a type name this process cannot build
            return self._refuse(ch, f"bad schema: {type_name} is not a message type this process knows ({err})")
        ch.publisher = self.bridge.publisher_for(ch.msg_type, ch.topic)
        self.bridge.remove_status(self._status_id(ch))
        return None

    def _deliver(self, ch: _ClientChannel, data: bytes) -> None:
        from aiorobot.msgs import deserialize

        if (ch.client, ch.id) not in self._channels:
            return  # unadvertised or the client left while this was queued
        if ch.publisher is None and self._open(ch) is not None:
            self.refused += 1
            return
        try:
            msg = deserialize(data, ch.msg_type)
        except Exception as err:  # noqa: BLE001 - whatever the bytes are, they are not this type
            self.refused += 1
            ch.last_error = -1e9  # every undecodable message is worth a line
            self._refuse(ch, f"bad message: {len(data)} bytes do not decode as {ch.msg_type.__msgtype__} ({err})")
            return
        ch.publisher.publish(msg)
        self.published += 1

    def _refuse(self, ch: _ClientChannel, reason: str) -> str:
        now = time.monotonic()
        if now - ch.last_error >= _REPEAT_SEC:
            ch.last_error = now
            self.bridge.error_status(f"client {ch.client}: cannot publish on {ch.topic}: {reason}; nothing published",
                                     self._status_id(ch))
        return reason

    @staticmethod
    def _status_id(ch: _ClientChannel) -> str:
        return f"clientPublish/{ch.client}/{ch.id}"

    def _endpoints(self, topic: str) -> list[Any]:
        info = self.bridge.runtime.graph.topic(topic)
        return [] if info is None else [*info.publishers, *info.subscriptions]
