"""Parameters of every node of the graph, in any process, for the Foxglove app.

Names are ``<node fully qualified name>.<parameter>`` (``/amcl.max_particles``), as ROS 2's
foxglove_bridge shows them. Every node is reached through its ``rcl_interfaces`` parameter
services (``~/list_parameters``, ``~/get_parameters``, ``~/set_parameters``), so a node in another
process (over zenoh) or a ROS 2 node answers like one in the bridge's own runtime. A node that
does not answer within ``timeout_sec`` is left out with one warning line naming it.

``parametersSubscribe``: the bridge subscribes ``/parameter_events`` and sends the new value of a
parameter a client subscribed to whenever its node reports a change.

The server calls in from its own thread and waits for the answer; the calls run on the bridge
node's loop.
"""

from __future__ import annotations

import asyncio
import threading
from typing import TYPE_CHECKING, Any

from ..lowlevel import node_loop

if TYPE_CHECKING:
    from ._bridge import FoxgloveBridge

__all__ = ["GraphParameters", "to_foxglove"]


class GraphParameters:
    """Get, set and watch the parameters of every node the bridge's runtime can see."""

    def __init__(self, bridge: FoxgloveBridge, *, timeout_sec: float = 3.0) -> None:
        self.bridge = bridge
        self.timeout_sec = timeout_sec
        self._clients: dict[tuple[str, str], Any] = {}
        self._subscribed: set[str] = set()
        self._lock = threading.Lock()
        self._silent: set[str] = set()

    def start(self) -> None:
        """Subscribe ``/parameter_events`` (call on the bridge node's loop, or before it runs)."""
        from aiorobot.msgs.rcl_interfaces import ParameterEvent
        from aiorobot.parameters import qos_profile_parameter_events

        self.bridge.create_subscription(ParameterEvent, "/parameter_events", self._on_event, qos_profile_parameter_events)

    # -- from the server's thread ----------------------------------------------------------

    def get(self, names: list[str]) -> list[Any]:
        return self._run(self._get(names))

    def set(self, params: list[Any]) -> list[Any]:
        return self._run(self._set(params))

    def subscribe(self, names: list[str]) -> None:
        with self._lock:
            self._subscribed.update(names)

    def unsubscribe(self, names: list[str]) -> None:
        with self._lock:
            self._subscribed.difference_update(names)

    def _run(self, coro: Any) -> list[Any]:
        loop = node_loop(self.bridge)
        if loop is None:
            coro.close()
            return []
        try:
            return list(asyncio.run_coroutine_threadsafe(coro, loop).result(timeout=self.timeout_sec * 3 + 5.0))
        except Exception as err:  # noqa: BLE001 - the bridge is stopping, or the graph did not answer: say so
            self.bridge.error_status(f"foxglove: parameter request failed ({type(err).__name__} {err})".rstrip(), "parameters")
            return []

    # -- on the bridge node's loop ---------------------------------------------------------

    def _nodes(self) -> list[str]:
        """Nodes that offer ``~/get_parameters`` (fully qualified names), longest first."""
        served = {s.name for s in self.bridge.runtime.graph.services if s.servers}
        names = {n.fully_qualified_name for n in self.bridge.runtime.graph.nodes}
        return sorted((n for n in names if f"{n.rstrip('/')}/get_parameters" in served), key=len, reverse=True)

    def _split(self, full: str, nodes: list[str]) -> tuple[str, str] | None:
        for node in nodes:  # longest first: /a/b.x belongs to /a/b, not /a
            if full.startswith(node + ".") and len(full) > len(node) + 1:
                return node, full[len(node) + 1:]
        return None

    async def _get(self, names: list[str]) -> list[Any]:
        nodes = self._nodes()
        if names:
            wanted: dict[str, list[str]] = {}
            for full in names:
                split = self._split(full, nodes)
                if split is not None:
                    wanted.setdefault(split[0], []).append(split[1])
            jobs = [self._node_values(node, pnames) for node, pnames in wanted.items()]
        else:
            jobs = [self._node_values(node, None) for node in nodes]
        out: list[Any] = []
        for values in await asyncio.gather(*jobs):
            out.extend(values)
        return out

    async def _node_values(self, node: str, pnames: list[str] | None) -> list[Any]:
        from aiorobot.msgs import rcl_interfaces as ri
        from aiorobot.parameters import parameter_value_to_python

        try:
            if pnames is None:
                listed = await self._call(node, ri.ListParameters, "list_parameters", ri.ListParameters.Request())
                pnames = list(listed.result.names)
            got = await self._call(node, ri.GetParameters, "get_parameters", ri.GetParameters.Request(names=pnames))
        except Exception as err:  # noqa: BLE001 - a node that left or does not answer: leave it out, say so
            self._warn_once(node, f"foxglove: parameters of {node} left out: {type(err).__name__} {err}".rstrip())
            return []
        self._silent.discard(node)
        values = list(got.values)
        if len(values) != len(pnames):  # rclpy's answer when a name is unknown: no values at all
            return []
        return [to_foxglove_parameter(f"{node}.{n}", parameter_value_to_python(v)) for n, v in zip(pnames, values)]

    async def _set(self, params: list[Any]) -> list[Any]:
        from aiorobot import Parameter
        from aiorobot.msgs import rcl_interfaces as ri

        nodes = self._nodes()
        by_node: dict[str, list[Any]] = {}
        for p in params:
            split = self._split(p.name, nodes)
            if split is None:
                self.bridge.error_status(f"foxglove: cannot set {p.name}: no node of the graph has that name "
                                         "(expected /<node>.<parameter>)", f"parameters/{p.name}")
                continue
            by_node.setdefault(split[0], []).append(Parameter(split[1], value=from_foxglove(p.get_value())).to_parameter_msg())

        async def set_on(node: str, msgs: list[Any]) -> None:
            try:
                answer = await self._call(node, ri.SetParameters, "set_parameters", ri.SetParameters.Request(parameters=msgs))
            except Exception as err:  # noqa: BLE001 - say so; the values read back show what holds
                self.bridge.error_status(f"foxglove: setting parameters of {node} failed ({type(err).__name__} {err})",
                                         f"parameters/{node}")
                return
            for msg, result in zip(msgs, answer.results):
                if not result.successful:
                    self.bridge.error_status(f"foxglove: {node}.{msg.name} not set: {result.reason}", f"parameters/{node}.{msg.name}")

        await asyncio.gather(*(set_on(node, msgs) for node, msgs in by_node.items()))
        return await self._get([p.name for p in params])

    async def _call(self, node: str, srv: Any, service: str, request: Any) -> Any:
        key = (node, service)
        client = self._clients.get(key)
        if client is None:
            client = self._clients[key] = self.bridge.create_client(srv, f"{node.rstrip('/')}/{service}")
        # wall-clock bound: the node clock may be sim time, paused
        return await asyncio.wait_for(client.call(request), self.timeout_sec)

    def _on_event(self, event: Any) -> None:
        from aiorobot.parameters import parameter_value_to_python

        server = self.bridge.server
        with self._lock:
            subscribed = set(self._subscribed)
        if not subscribed or server is None:
            return
        node = str(event.node)
        out = []
        for p in (*event.new_parameters, *event.changed_parameters):
            full = f"{node}.{p.name}"
            if full in subscribed:
                out.append(to_foxglove_parameter(full, parameter_value_to_python(p.value)))
        if out:
            server.publish_parameter_values(out)

    def _warn_once(self, node: str, text: str) -> None:
        if node not in self._silent:
            self._silent.add(node)
            self.bridge.get_logger().warning(text)


def to_foxglove_parameter(name: str, value: Any) -> Any:
    from foxglove.websocket import Parameter

    return Parameter(name) if value is None else Parameter(name, value=to_foxglove(value))


def to_foxglove(value: Any) -> Any:
    """A parameter's Python value as a foxglove ``ParameterValue``."""
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
        return ParameterValue.Array([to_foxglove(v) for v in value])
    return ParameterValue.String(repr(value))


def from_foxglove(value: Any) -> Any:
    if isinstance(value, list):
        return [from_foxglove(v) for v in value]
    return value
