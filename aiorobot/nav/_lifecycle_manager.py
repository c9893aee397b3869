"""``LifecycleManager``: nav2_lifecycle_manager's node: brings managed (lifecycle) nodes up in order,
down in reverse, and watches that they stay alive.

Parameters (Nav2's names): ``node_names`` (the managed nodes, in bring-up order), ``autostart``
(configure and activate them once the manager starts), ``bond_timeout`` (s; 0 disables the
watch), ``attempt_respawn_reconnection`` and ``bond_respawn_max_duration`` (s), ``service_timeout``
(s to wait for a node's lifecycle services).

Services, as Nav2's: ``~/manage_nodes`` (nav2_msgs/ManageLifecycleNodes: STARTUP = configure then
activate every node in order; PAUSE = deactivate, RESUME = activate; RESET = deactivate + clean up;
SHUTDOWN = deactivate, clean up, shut down; CONFIGURE; CLEANUP; the downward ones in reverse order)
and ``~/is_active`` (std_srvs/Trigger).

Liveliness, bond-like: Nav2's managed nodes heartbeat over bondcpp; aiorobot's lifecycle nodes have
no bond, so the manager asks each node's ``~/get_state`` every ``bond_heartbeat_period`` (s). A node
that has not answered for ``bond_timeout`` counts as down, as a broken bond does: the manager logs
Nav2's CRITICAL FAILURE line, hard-resets the other nodes (deactivate + clean up) and, with
``attempt_respawn_reconnection``, brings everything up again once the node answers within
``bond_respawn_max_duration``.
"""

from __future__ import annotations

import asyncio
import enum
from dataclasses import dataclass
from typing import Any

from .._core._node import Node

__all__ = ["LifecycleManager", "LifecycleManagerStatistics", "ManagerState"]


class ManagerState(enum.Enum):
    """nav2_lifecycle_manager's NodeState of the managed system."""

    UNCONFIGURED = "unconfigured"
    INACTIVE = "inactive"
    ACTIVE = "active"
    FINALIZED = "finalized"
    UNKNOWN = "unknown"


@dataclass(frozen=True, slots=True)
class LifecycleManagerStatistics:
    state: ManagerState
    #: nodes found down by the liveliness watch (each time counted)
    bond_failures: int
    #: the node last found down, if any
    last_down: str | None


class LifecycleManager(Node):
    """See the module doc.

    rclpy difference: liveliness is a ``get_state`` poll every ``bond_heartbeat_period``, not a bond;
    the node found down is left out of the hard reset.
    """

    def __init__(self, node_name: str = "lifecycle_manager", **kwargs: Any) -> None:
        super().__init__(node_name, **kwargs)
        d = self.declare_parameter
        self.node_names = [str(n) for n in d("node_names", [""]).value if str(n)]
        self.autostart = bool(d("autostart", False).value)
        self.bond_timeout = float(d("bond_timeout", 4.0).value)
        self.bond_heartbeat_period = float(d("bond_heartbeat_period", 0.25).value)
        self.attempt_respawn_reconnection = bool(d("attempt_respawn_reconnection", True).value)
        self.bond_respawn_max_duration = float(d("bond_respawn_max_duration", 10.0).value)
        self.service_timeout = float(d("service_timeout", 5.0).value)
        if not self.node_names:
            raise ValueError(f"lifecycle manager {self.get_name()}: parameter node_names: expected the managed nodes' "
                             "names in bring-up order, found none")
        from aiorobot.msgs.lifecycle_msgs import ChangeState, GetState
        from aiorobot.msgs.nav2_msgs import ManageLifecycleNodes
        from aiorobot.msgs.std_srvs import Trigger

        self._change = {n: self.create_client(ChangeState, f"/{n.lstrip('/')}/change_state") for n in self.node_names}
        self._get = {n: self.create_client(GetState, f"/{n.lstrip('/')}/get_state") for n in self.node_names}
        self.create_service(ManageLifecycleNodes, "~/manage_nodes", self._manage)
        self.create_service(Trigger, "~/is_active", self._is_active)
        self.state = ManagerState.UNCONFIGURED
        self.bond_failures = 0
        self.last_down: str | None = None
        self._watch: asyncio.Task[None] | None = None
        self._lock = asyncio.Lock()

    def statistics(self) -> LifecycleManagerStatistics:
        return LifecycleManagerStatistics(self.state, self.bond_failures, self.last_down)

    async def on_start(self) -> None:
        if self.autostart:
            self.create_task(self.startup())

    # -- commands (ManageLifecycleNodes) ----------------------------------------------------

    async def startup(self) -> bool:
        async with self._lock:
            self.get_logger().info("Starting managed nodes bringup...")
            if not (await self._all("configure") and await self._all("activate")):
                self.get_logger().error("Failed to bring up all requested nodes. Aborting bringup.")
                self.state = ManagerState.UNKNOWN
                return False
            self.get_logger().info("Managed nodes are active")
            self.state = ManagerState.ACTIVE
            self._start_watch()
            return True

    async def shutdown(self) -> bool:
        async with self._lock:
            self._stop_watch()
            self.get_logger().info("Shutting down managed nodes...")
            self.state = ManagerState.FINALIZED
            for transition in ("deactivate", "cleanup", "unconfigured_shutdown"):
                await self._all(transition, hard=True)
            self.get_logger().info("Managed nodes have been shut down")
            return True

    async def reset(self, hard: bool = False) -> bool:
        async with self._lock:
            return await self._reset(hard)

    async def _reset(self, hard: bool, down: str | None = None) -> bool:
        self._stop_watch()
        self.get_logger().info("Resetting managed nodes...")
        if not (await self._all("deactivate", hard=hard, skip=down) and await self._all("cleanup", hard=hard, skip=down)) and not hard:
            self.get_logger().error("Failed to reset nodes: aborting reset")
            self.state = ManagerState.UNKNOWN
            return False
        self.get_logger().info("Managed nodes have been reset")
        self.state = ManagerState.UNCONFIGURED
        return True

    async def _step(self, transitions: tuple[str, ...], state: ManagerState, what: str, watch: bool = False) -> bool:
        async with self._lock:
            if not watch:
                self._stop_watch()
            for transition in transitions:
                if not await self._all(transition):
                    self.get_logger().error(f"Failed to {what} nodes: aborting {what}")
                    self.state = ManagerState.UNKNOWN
                    return False
            self.state = state
            if watch:
                self._start_watch()
            return True

    async def _manage(self, request: Any) -> Any:
        from aiorobot.msgs.nav2_msgs import ManageLifecycleNodes as M

        commands = {
            M.Request.STARTUP: self.startup, M.Request.SHUTDOWN: self.shutdown, M.Request.RESET: self.reset,
            M.Request.PAUSE: lambda: self._step(("deactivate",), ManagerState.INACTIVE, "pause"),
            M.Request.RESUME: lambda: self._step(("activate",), ManagerState.ACTIVE, "resume", watch=True),
            M.Request.CONFIGURE: lambda: self._step(("configure",), ManagerState.INACTIVE, "configure"),
            M.Request.CLEANUP: lambda: self._step(("cleanup",), ManagerState.UNCONFIGURED, "cleanup"),
        }
        command = commands.get(int(request.command))
        if command is None:
            self.get_logger().warning(f"manage_nodes: expected a command 0..6 (STARTUP..CLEANUP), found {request.command}")
            return M.Response(success=False)
        return M.Response(success=bool(await command()))

    def _is_active(self, request: Any) -> Any:
        from aiorobot.msgs.std_srvs import Trigger

        return Trigger.Response(success=self.state is ManagerState.ACTIVE)

    # -- transitions ----------------------------------------------------------------------------

    async def _all(self, transition: str, hard: bool = False, skip: str | None = None) -> bool:
        """``transition`` for every node (but ``skip``, one known down): configure / activate in order, the others in reverse."""
        order = self.node_names if transition in ("configure", "activate") else list(reversed(self.node_names))
        ok = True
        for name in order:
            if name == skip:
                continue
            if not await self._change_state(name, transition):
                ok = False
                if not hard:
                    return False
        return ok

    async def _change_state(self, name: str, transition: str) -> bool:
        from aiorobot.msgs.lifecycle_msgs import ChangeState, Transition

        client = self._change[name]
        if not await client.wait_for_service(timeout_sec=self.service_timeout):
            self.get_logger().error(f"{name}: no lifecycle service {client.srv_name} within {self.service_timeout:g} s "
                                    f"(is {name} a lifecycle node, and running?)")
            return False
        request = ChangeState.Request(transition=Transition(id=getattr(Transition, f"TRANSITION_{transition.upper()}")))
        try:
            response = await client.call(request, timeout_sec=self.service_timeout)
        except Exception as err:  # the node went away mid-call
            self.get_logger().error(f"{name}: {transition} failed ({err})")
            return False
        if not response.success:
            self.get_logger().error(f"{name}: {transition} refused")
        return bool(response.success)

    # -- liveliness ----------------------------------------------------------------------------

    def _start_watch(self) -> None:
        if self.bond_timeout > 0 and self._watch is None:
            self._watch = self.create_task(self._watch_nodes())

    def _stop_watch(self) -> None:
        if self._watch is not None and self._watch is not asyncio.current_task():
            self._watch.cancel()
        self._watch = None

    async def _alive(self, name: str) -> bool:
        client = self._get[name]
        if not client.service_is_ready():
            return False
        try:
            await client.call(client.srv_type.Request(), timeout_sec=self.bond_heartbeat_period)
        except Exception:
            return False
        return True

    async def _watch_nodes(self) -> None:
        clock = self.get_clock()
        last_seen = {n: clock.now() for n in self.node_names}
        while True:
            await clock.sleep_for(self.bond_heartbeat_period)
            now = clock.now()
            for name in self.node_names:
                if await self._alive(name):
                    last_seen[name] = now
                elif (now - last_seen[name]).nanoseconds / 1e9 >= self.bond_timeout:
                    self.bond_failures += 1
                    self.last_down = name
                    self.get_logger().error(f"CRITICAL FAILURE: SERVER {name} IS DOWN after not receiving a heartbeat "
                                            f"for {int(self.bond_timeout * 1000)} ms. Shutting down related nodes.")
                    async with self._lock:
                        self._watch = None  # this task ends here; a restart makes a new one
                        await self._reset(hard=True, down=name)
                    if self.attempt_respawn_reconnection:
                        self.create_task(self._respawn(name))
                    return

    async def _respawn(self, name: str) -> None:
        """Nav2's checkBondRespawnConnection: once ``name`` answers again, bring everything up again."""
        clock = self.get_clock()
        waited = 0.0
        while waited < self.bond_respawn_max_duration:
            if await self._alive(name):
                self.get_logger().info(f"{name} answers again: bringing the managed nodes back up")
                await self.startup()
                return
            await clock.sleep_for(1.0)
            waited += 1.0
        self.get_logger().error(f"{name} did not come back within bond_respawn_max_duration "
                                f"{self.bond_respawn_max_duration:g} s; the managed nodes stay down")
