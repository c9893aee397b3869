"""``LifecycleManager``: nav2_lifecycle_manager's node, bringing managed nodes up and down in order.

Parameters as Nav2's: ``node_names`` (the managed lifecycle nodes, in bring-up order; a relative
name resolves in the manager's namespace), ``autostart`` (start up once the node runs),
``bond_timeout`` (s; 0 turns the liveliness check off), ``service_timeout`` (s to wait for a
node's lifecycle service), ``attempt_respawn_reconnection`` and ``bond_respawn_max_duration``
(after a failure, start up again once every node answers again, for at most that long),
``bond_heartbeat_period`` (s between liveliness checks).

Services as Nav2's: ``~/manage_nodes`` (nav2_msgs/srv/ManageLifecycleNodes: STARTUP configures
then activates every node in order; PAUSE deactivates, RESUME activates, RESET deactivates and
cleans up, SHUTDOWN deactivates, cleans up and shuts down, each in reverse order; CONFIGURE and
CLEANUP) and ``~/is_active`` (std_srvs/srv/Trigger); ``~/managed_nodes_activated`` (std_msgs/Bool,
latched) says whether the managed nodes are active. A command runs to its end before the next
(one mutually exclusive callback group, as Nav2's); a transition that fails stops the command,
logs the node and why, and leaves the manager's state UNKNOWN.

Liveliness, bond-like: Nav2 forms a ``bond`` (heartbeats on ``/bond``) with each node it has
activated. aiorobot's graph already tracks which nodes are alive (a process that dies leaves it
with its transport session), so the manager watches that instead and the managed nodes need
nothing extra: a managed node gone from the graph for ``bond_timeout`` is a broken bond, and as
Nav2 the manager logs a critical failure and resets the other nodes (a hard reset: past a failed
transition), then tries to bring the system back up while it waits for the node to return.
"""

from __future__ import annotations

import enum
from typing import Any

from .._core._groups import MutuallyExclusiveCallbackGroup
from .._core._node import Node
from ..lifecycle import LifecycleState, LifecycleTransition

__all__ = ["LifecycleManager", "ManagedState"]

_T = LifecycleTransition
#: each transition the manager requests, the state a node must reach, and Nav2's log verb
_TARGET = {
    _T.CONFIGURE: (LifecycleState.INACTIVE, "Configuring"),
    _T.CLEANUP: (LifecycleState.UNCONFIGURED, "Cleaning up"),
    _T.ACTIVATE: (LifecycleState.ACTIVE, "Activating"),
    _T.DEACTIVATE: (LifecycleState.INACTIVE, "Deactivating"),
    _T.UNCONFIGURED_SHUTDOWN: (LifecycleState.FINALIZED, "Shutting down"),
}


class ManagedState(enum.Enum):
    """The managed nodes' state as the manager sees it (nav2_lifecycle_manager's NodeState)."""

    UNCONFIGURED = "unconfigured"
    INACTIVE = "inactive"
    ACTIVE = "active"
    FINALIZED = "finalized"
    UNKNOWN = "unknown"  # a transition failed part way


class LifecycleManager(Node):
    """nav2_lifecycle_manager's LifecycleManager: see the module docstring.

    ``await manager.startup()`` (and ``pause``, ``resume``, ``reset``, ``shutdown``, ``configure``,
    ``cleanup``) run the same commands as the ``~/manage_nodes`` service and return its success.

    rclpy difference: (Nav2's) liveliness is the graph's, not a bond on ``/bond`` (the managed nodes
    need no bond code; ``bond_heartbeat_period`` is how often it is checked); a hard reset goes on
    past a node whose service is gone; no diagnostics are published.
    """

    def __init__(self, node_name: str = "lifecycle_manager", namespace: str = "", **kwargs: Any) -> None:
        super().__init__(node_name, namespace=namespace, **kwargs)
        from aiorobot import Parameter, QoSProfile
        from aiorobot.msgs.nav2_msgs import ManageLifecycleNodes
        from aiorobot.msgs.std_msgs import Bool
        from aiorobot.msgs.std_srvs import Trigger

        from ._map_server import MAP_QOS

        names = self.declare_parameter("node_names", Parameter.Type.STRING_ARRAY)
        if names.value is None or not list(names.value):
            raise ValueError(f"{self.get_name()}: parameter node_names: expected the managed nodes' names "
                             f"(a non-empty string list, in bring-up order), found {names.value!r}")
        self.node_names: list[str] = [str(n) for n in names.value]
        self.autostart = bool(self.declare_parameter("autostart", False).value)
        self.bond_timeout = float(self.declare_parameter("bond_timeout", 4.0).value)
        self.service_timeout = float(self.declare_parameter("service_timeout", 5.0).value)
        self.bond_respawn_max_duration = float(self.declare_parameter("bond_respawn_max_duration", 10.0).value)
        self.attempt_respawn_reconnection = bool(self.declare_parameter("attempt_respawn_reconnection", True).value)
        self.bond_heartbeat_period = float(self.declare_parameter("bond_heartbeat_period", 0.25).value)
        if self.bond_heartbeat_period <= 0.0:
            raise ValueError(f"{self.get_name()}: parameter bond_heartbeat_period: expected > 0 s, "
                             f"found {self.bond_heartbeat_period!r}")
        self.state = ManagedState.UNCONFIGURED
        self._group = MutuallyExclusiveCallbackGroup()
        self._fq = {name: self._qualify(name) for name in self.node_names}
        self._lifecycle: dict[str, tuple[Any, Any]] = {}
        #: the activated nodes whose liveliness is watched, and since when (ns) each has been missing
        self._bonds: dict[str, int | None] = {}
        # made once and paused (cancel / reset): destroying a timer would cancel the callback that stops it
        self._bond_timer = self.create_timer(self.bond_heartbeat_period, self._check_bonds,
                                             callback_group=self._group, autostart=False)
        self._respawn_timer = self.create_timer(1.0, self._check_respawn, callback_group=self._group, autostart=False)
        self._respawn_start: int | None = None
        self._closing = False
        self._active_pub = self.create_publisher(Bool, "~/managed_nodes_activated", QoSProfile(
            reliability=MAP_QOS.reliability, durability=MAP_QOS.durability, depth=1))
        self.create_service(ManageLifecycleNodes, "~/manage_nodes", self._on_manage, callback_group=self._group)
        self.create_service(Trigger, "~/is_active", lambda _r: Trigger.Response(success=self.is_active()),
                            callback_group=self._group)
        self._set_state(ManagedState.UNCONFIGURED)

    def __repr__(self) -> str:
        return f"<LifecycleManager {self.get_fully_qualified_name()} {self.state.value} nodes={self.node_names}>"

    def _qualify(self, name: str) -> str:
        if name.startswith("/"):
            return name
        ns = self.get_namespace().rstrip("/")
        return f"{ns}/{name}"

    def is_active(self) -> bool:
        """Whether the managed nodes are all active (``~/is_active``)."""
        return self.state is ManagedState.ACTIVE

    def _set_state(self, state: ManagedState) -> None:
        from aiorobot.msgs.std_msgs import Bool

        self.state = state
        self._active_pub.publish(Bool(data=self.is_active()))

    async def on_start(self) -> None:
        if self.autostart:
            self.create_task(self._locked(self.startup), name=f"{self.get_name()} autostart")

    async def on_shutdown(self) -> None:
        # As Nav2's rcl pre-shutdown: drop the bonds, so nodes stopping with the runtime are no failure.
        self._closing = True
        self._stop_bond_timer()
        self._stop_respawn_timer()

    async def _locked(self, command: Any) -> bool:
        async with self._group:
            return bool(await command())

    async def _on_manage(self, request: Any) -> Any:
        from aiorobot.msgs.nav2_msgs import ManageLifecycleNodes

        r = ManageLifecycleNodes.Request
        commands = {r.STARTUP: self.startup, r.PAUSE: self.pause, r.RESUME: self.resume, r.RESET: self.reset,
                    r.SHUTDOWN: self.shutdown, r.CONFIGURE: self.configure, r.CLEANUP: self.cleanup}
        command = commands.get(int(request.command))
        if command is None:
            self.get_logger().error(f"~/manage_nodes: expected a command 0-6 (STARTUP ... CLEANUP), "
                                    f"found {request.command}")
            return ManageLifecycleNodes.Response(success=False)
        return ManageLifecycleNodes.Response(success=await command())

    # -- commands (Nav2's startup, pause, resume, reset, shutdown, configure, cleanup) --------------

    async def startup(self) -> bool:
        """Configure, then activate, every managed node in order."""
        self._info("Starting managed nodes bringup...")
        if not (await self._all(_T.CONFIGURE) and await self._all(_T.ACTIVATE)):
            self.get_logger().error("Failed to bring up all requested nodes. Aborting bringup.")
            self._set_state(ManagedState.UNKNOWN)
            return False
        self._info("Managed nodes are active")
        self._set_state(ManagedState.ACTIVE)
        self._start_bond_timer()
        return True

    async def configure(self) -> bool:
        """Configure every managed node in order."""
        return await self._command("Configuring managed nodes...", [_T.CONFIGURE], ManagedState.INACTIVE,
                                   "Failed to configure all requested nodes. Aborting bringup.")

    async def cleanup(self) -> bool:
        """Clean up every managed node, in reverse order."""
        return await self._command("Cleaning up managed nodes...", [_T.CLEANUP], ManagedState.UNCONFIGURED,
                                   "Failed to cleanup all requested nodes. Aborting cleanup.")

    async def pause(self) -> bool:
        """Deactivate every managed node, in reverse order."""
        self._stop_bond_timer()
        return await self._command("Pausing managed nodes...", [_T.DEACTIVATE], ManagedState.INACTIVE,
                                   "Failed to pause nodes: aborting pause")

    async def resume(self) -> bool:
        """Activate every managed node in order."""
        ok = await self._command("Resuming managed nodes...", [_T.ACTIVATE], ManagedState.ACTIVE,
                                 "Failed to resume nodes: aborting resume")
        if ok:
            self._start_bond_timer()
        return ok

    async def reset(self, hard: bool = False) -> bool:
        """Deactivate, then clean up, every managed node in reverse order; ``hard`` goes on past failures."""
        self._stop_bond_timer()
        self._info("Resetting managed nodes...")
        # Nav2's hard reset stops at a node whose service is gone (an exception ends its loop), leaving
        # the nodes after it active; here it goes on, as its comment means: "transition all still active down"
        ok = await self._all(_T.DEACTIVATE, hard)
        ok = (ok or hard) and await self._all(_T.CLEANUP, hard) and ok
        if not ok and not hard:
            self.get_logger().error("Failed to reset nodes: aborting reset")
            self._set_state(ManagedState.UNKNOWN)
            return False
        self._info("Managed nodes have been reset")
        self._set_state(ManagedState.UNCONFIGURED)
        return True

    async def shutdown(self) -> bool:
        """Deactivate, clean up and shut down every managed node, in reverse order (always succeeds, as Nav2)."""
        self._stop_bond_timer()
        self._info("Shutting down managed nodes...")
        self._set_state(ManagedState.FINALIZED)
        for transition in (_T.DEACTIVATE, _T.CLEANUP, _T.UNCONFIGURED_SHUTDOWN):
            await self._all(transition)
        self._info("Managed nodes have been shut down")
        return True

    async def _command(self, start: str, transitions: list[LifecycleTransition], reached: ManagedState,
                       failure: str) -> bool:
        self._info(start)
        for transition in transitions:
            if not await self._all(transition):
                self.get_logger().error(failure)
                self._set_state(ManagedState.UNKNOWN)
                return False
        self._set_state(reached)
        return True

    # -- transitions of the managed nodes ------------------------------------------------------------

    async def _all(self, transition: LifecycleTransition, hard: bool = False) -> bool:
        """``transition`` on every node, in order for configure/activate, else in reverse; the first
        failure stops unless ``hard``."""
        forward = transition in (_T.CONFIGURE, _T.ACTIVATE)
        ok = True
        for name in self.node_names if forward else reversed(self.node_names):
            if not await self._change(name, transition):
                ok = False
                if not hard:
                    return False
        return ok

    def _lifecycle_clients(self, name: str) -> tuple[Any, Any]:
        from aiorobot.msgs.lifecycle_msgs import ChangeState, GetState

        if name not in self._lifecycle:
            fq = self._fq[name]
            self._lifecycle[name] = (self.create_client(ChangeState, f"{fq}/change_state"),
                                   self.create_client(GetState, f"{fq}/get_state"))
        return self._lifecycle[name]

    async def _change(self, name: str, transition: LifecycleTransition) -> bool:
        from aiorobot.msgs.lifecycle_msgs import ChangeState, Transition

        target, verb = _TARGET[transition]
        self._info(f"{verb} {name}")
        change, get = self._lifecycle_clients(name)
        try:
            if not await change.wait_for_service(timeout_sec=self.service_timeout):
                raise RuntimeError(f"no service {change.srv_name} within service_timeout {self.service_timeout:g} s "
                                   f"(is {self._fq[name]} a lifecycle node, and running?)")
            request = ChangeState.Request(transition=Transition(id=int(transition)))
            response = await change.call(request, timeout_sec=self.service_timeout)
            state = await self._state_of(name, get)
        except Exception as err:  # noqa: BLE001 - any failure of a node is logged with it, as Nav2's
            self.get_logger().error(f"Failed to change state for node: {name}. Exception: {err}.")
            return False
        if not response.success or state is not target:
            found = state.label if state is not None else "no answer"
            self.get_logger().error(f"Failed to change state for node: {name} (expected {target.label}, "
                                    f"found {found})")
            return False
        if transition is _T.ACTIVATE:
            return await self._form_bond(name)
        if transition is _T.DEACTIVATE:
            self._bonds.pop(name, None)
        return True

    async def _state_of(self, name: str, get: Any) -> LifecycleState | None:
        from aiorobot.msgs.lifecycle_msgs import GetState

        if not await get.wait_for_service(timeout_sec=self.service_timeout):
            return None
        response = await get.call(GetState.Request(), timeout_sec=self.service_timeout)
        return LifecycleState(int(response.current_state.id))

    # -- liveliness (Nav2's bond) ----------------------------------------------------------------------

    def _alive(self, name: str) -> bool:
        return self._fq[name] in self.get_fully_qualified_node_names()

    async def _form_bond(self, name: str) -> bool:
        if self.bond_timeout <= 0.0 or name in self._bonds:
            return True
        if not await self.wait_for_node(self._fq[name], self.bond_timeout / 2):
            self.get_logger().error(f"Server {name} was unable to be reached after {self.bond_timeout:.2f}s by "
                                    f"bond. This server may be misconfigured.")
            return False
        self._bonds[name] = None
        self._info(f"Server {name} connected with bond.")
        return True

    def _start_bond_timer(self) -> None:
        if self.bond_timeout > 0.0 and self._bond_timer.is_canceled() and not self._closing:
            self._info("Creating bond timer...")
            self._bond_timer.reset()

    def _stop_bond_timer(self) -> None:
        if not self._bond_timer.is_canceled():
            self._info("Terminating bond timer...")
            self._bond_timer.cancel()

    def _stop_respawn_timer(self) -> None:
        self._respawn_timer.cancel()
        self._respawn_start = None

    async def _check_bonds(self) -> None:
        if self._closing or not self.is_active() or not self._bonds:
            return
        now = self.now().nanoseconds
        for name in list(self._bonds):
            if self._alive(name):
                self._bonds[name] = None
                continue
            since = self._bonds[name] = self._bonds[name] or now
            if now - since < round(self.bond_timeout * 1e9):
                continue
            self._info(f"Have not received a heartbeat from {name}.")
            self.get_logger().error(f"CRITICAL FAILURE: SERVER {name} IS DOWN after not receiving a heartbeat for "
                                    f"{round(self.bond_timeout * 1000)} ms. Shutting down related nodes.")
            await self.reset(hard=True)
            self._bonds.clear()  # the crashed node's bond did not go with a failed transition
            if self.attempt_respawn_reconnection and not self._closing:
                self._respawn_timer.reset()
            return

    async def _check_respawn(self) -> None:
        now = self.now().nanoseconds
        if self._respawn_start is None:
            self._respawn_start = now
        if self.is_active() or self._closing:
            self._stop_respawn_timer()
            return
        for name in self.node_names:
            try:
                state = await self._state_of(name, self._lifecycle_clients(name)[1])
            except Exception:  # noqa: BLE001 - a node not answering yet is what is being waited for
                state = None
            if state is None:
                break
        else:
            self._info("Successfully re-established connections from server respawns, starting back up.")
            self._stop_respawn_timer()
            await self.startup()
            return
        if now - self._respawn_start >= round(self.bond_respawn_max_duration * 1e9):
            self._info("Failed to re-establish connection from a server crash after maximum timeout.")
            self._stop_respawn_timer()

    def _info(self, text: str) -> None:
        self.get_logger().info(text)
