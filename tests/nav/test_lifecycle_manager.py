"""nav2_lifecycle_manager's behaviour: bring-up in order, tear-down in reverse, a failing node stops
the bring-up, ``~/manage_nodes`` and ``~/is_active`` as services, and the bond-like liveliness check
(a managed node leaving the graph resets the others; its return brings the system back up)."""

from __future__ import annotations

import asyncio
import logging

import pytest

from aiorobot import Node
from aiorobot.lifecycle import LifecycleNode, LifecycleState, TransitionCallbackReturn
from aiorobot.msgs.nav2_msgs import ManageLifecycleNodes
from aiorobot.msgs.std_msgs import Bool
from aiorobot.msgs.std_srvs import Trigger
from aiorobot.nav import LifecycleManager, ManagedState

S = LifecycleState


class Managed(LifecycleNode):
    """Appends (hook, name) to a shared journal; ``fail`` names a hook that returns FAILURE."""

    def __init__(self, name: str, journal: list[tuple[str, str]], fail: str = "") -> None:
        super().__init__(name)
        self.journal = journal
        self.fail = fail

    async def _hook(self, hook: str) -> TransitionCallbackReturn:
        self.journal.append((hook, self.get_name()))
        return TransitionCallbackReturn.FAILURE if hook == self.fail else TransitionCallbackReturn.SUCCESS

    async def on_configure(self, state):
        return await self._hook("configure")

    async def on_activate(self, state):
        return await self._hook("activate")

    async def on_deactivate(self, state):
        return await self._hook("deactivate")

    async def on_cleanup(self, state):
        return await self._hook("cleanup")

    async def on_shutdown_transition(self, state):
        return await self._hook("shutdown")


NAMES = ["map_server", "amcl", "bt_navigator"]


def _manager(**params) -> LifecycleManager:
    overrides = {"node_names": NAMES, "service_timeout": 1.0, **params}
    return LifecycleManager("lifecycle_manager_navigation", parameter_overrides=overrides)


async def _poll(predicate, what: str, bound: int = 2000) -> None:
    for _ in range(bound):
        if predicate():
            return
        await asyncio.sleep(0.005)
    raise AssertionError(f"not reached: {what}")


async def test_startup_brings_nodes_up_in_order_and_shutdown_takes_them_down_in_reverse(runtime):
    journal: list[tuple[str, str]] = []
    nodes = [runtime.add_node(Managed(n, journal)) for n in NAMES]
    manager = runtime.add_node(_manager(bond_timeout=0.0))
    assert manager.state is ManagedState.UNCONFIGURED
    assert await manager.startup()
    assert journal == [("configure", n) for n in NAMES] + [("activate", n) for n in NAMES]
    assert [n.current_state for n in nodes] == [S.ACTIVE] * 3 and manager.is_active()
    journal.clear()
    assert await manager.pause() and manager.state is ManagedState.INACTIVE
    assert await manager.resume() and manager.is_active()
    assert journal == [("deactivate", n) for n in reversed(NAMES)] + [("activate", n) for n in NAMES]
    journal.clear()
    assert await manager.shutdown()
    rev = list(reversed(NAMES))
    assert journal == [("deactivate", n) for n in rev] + [("cleanup", n) for n in rev] + [("shutdown", n) for n in rev]
    assert [n.current_state for n in nodes] == [S.FINALIZED] * 3
    assert manager.state is ManagedState.FINALIZED


async def test_a_node_failing_to_configure_stops_the_bringup_and_says_which(runtime, caplog):
    journal: list[tuple[str, str]] = []
    runtime.add_node(Managed("map_server", journal))
    runtime.add_node(Managed("amcl", journal, fail="configure"))
    runtime.add_node(Managed("bt_navigator", journal))
    manager = runtime.add_node(_manager(bond_timeout=0.0))
    with caplog.at_level(logging.ERROR):
        assert not await manager.startup()
    assert journal == [("configure", "map_server"), ("configure", "amcl")]  # bt_navigator never touched
    assert manager.state is ManagedState.UNKNOWN and not manager.is_active()
    errors = [r.getMessage() for r in caplog.records if r.levelno == logging.ERROR]
    assert errors == ["Failed to change state for node: amcl (expected inactive, found unconfigured)",
                      "Failed to bring up all requested nodes. Aborting bringup."]


async def test_a_missing_node_fails_the_bringup_within_service_timeout(runtime, caplog):
    journal: list[tuple[str, str]] = []
    runtime.add_node(Managed("map_server", journal))
    manager = runtime.add_node(_manager(bond_timeout=0.0, service_timeout=0.2))
    with caplog.at_level(logging.ERROR):
        assert not await manager.startup()
    assert ("Failed to change state for node: amcl. Exception: no service /amcl/change_state within "
            "service_timeout 0.2 s (is /amcl a lifecycle node, and running?).") in caplog.messages


async def test_manage_nodes_and_is_active_services_with_autostart(runtime):
    journal: list[tuple[str, str]] = []
    nodes = [runtime.add_node(Managed(n, journal)) for n in NAMES]
    manager = runtime.add_node(_manager(autostart=True, bond_timeout=0.0))
    user = runtime.add_node(Node("user"))
    latched: list[bool] = []
    from aiorobot.nav._map_server import MAP_QOS

    user.create_subscription(Bool, "/lifecycle_manager_navigation/managed_nodes_activated",
                             lambda m: latched.append(m.data), MAP_QOS)
    is_active = user.create_client(Trigger, "/lifecycle_manager_navigation/is_active")
    manage = user.create_client(ManageLifecycleNodes, "/lifecycle_manager_navigation/manage_nodes")
    assert await is_active.wait_for_service(timeout_sec=5.0) and await manage.wait_for_service(timeout_sec=5.0)
    await _poll(manager.is_active, "autostart")
    assert (await is_active.call(Trigger.Request())).success
    await _poll(lambda: latched and latched[-1], "managed_nodes_activated true")
    request = ManageLifecycleNodes.Request(command=ManageLifecycleNodes.Request.RESET)
    assert (await manage.call(request, timeout_sec=10.0)).success
    assert [n.current_state for n in nodes] == [S.UNCONFIGURED] * 3
    assert not (await is_active.call(Trigger.Request())).success
    await _poll(lambda: latched[-1] is False, "managed_nodes_activated false")
    request = ManageLifecycleNodes.Request(command=ManageLifecycleNodes.Request.STARTUP)
    assert (await manage.call(request, timeout_sec=10.0)).success and manager.is_active()


async def test_a_node_leaving_the_graph_resets_the_others_and_its_return_restarts_them(runtime, caplog):
    journal: list[tuple[str, str]] = []
    nodes = [runtime.add_node(Managed(n, journal)) for n in NAMES]
    manager = runtime.add_node(_manager(bond_timeout=0.1, bond_heartbeat_period=0.02, service_timeout=0.2))
    assert await manager.startup()
    with caplog.at_level(logging.ERROR):
        runtime.remove_node(nodes[1])  # amcl "crashes"
        await _poll(lambda: manager.state is ManagedState.UNCONFIGURED, "reset after the broken bond")
    assert ("CRITICAL FAILURE: SERVER amcl IS DOWN after not receiving a heartbeat for 100 ms. "
            "Shutting down related nodes.") in caplog.messages
    assert [nodes[0].current_state, nodes[2].current_state] == [S.UNCONFIGURED, S.UNCONFIGURED]
    respawned = runtime.add_node(Managed("amcl", journal))  # the node comes back: the manager starts up again
    await _poll(manager.is_active, "restart after respawn", bound=4000)
    assert [nodes[0].current_state, respawned.current_state, nodes[2].current_state] == [S.ACTIVE] * 3


def test_node_names_is_required():
    with pytest.raises(ValueError, match=r"^lifecycle_manager: parameter node_names: expected the managed nodes' "
                                         r"names \(a non-empty string list, in bring-up order\), found None$"):
        LifecycleManager()
