"""nav2_lifecycle_manager's behaviour: bring-up in order, shut-down in reverse, manage_nodes / is_active,
the liveliness watch resetting the others when a managed node goes away, and BasicNavigator's
lifecycleStartup / lifecycleShutdown; real lifecycle nodes and services on sim time."""

from __future__ import annotations

import asyncio

import pytest

from aiorobot.lifecycle import LifecycleNode, LifecycleState
from aiorobot.nav import LifecycleManager, ManagerState, Navigator
from aiorobot.testing import SimClock

LOG: list[str] = []


class Managed(LifecycleNode):
    """Logs each transition hook it runs."""

    async def on_configure(self, state):
        LOG.append(f"configure {self.get_name()}")

    async def on_activate(self, state):
        LOG.append(f"activate {self.get_name()}")

    async def on_deactivate(self, state):
        LOG.append(f"deactivate {self.get_name()}")

    async def on_cleanup(self, state):
        LOG.append(f"cleanup {self.get_name()}")

    async def on_shutdown_transition(self, state):
        LOG.append(f"shutdown {self.get_name()}")


async def _settle(sim: SimClock, done, limit_sec: float = 10.0) -> None:
    t = 0.0
    while not done() and t < limit_sec:
        await sim.advance(0.05, step_sec=0.05)
        t += 0.05


@pytest.fixture
async def graph(sim_runtime):
    LOG.clear()
    sim = SimClock(sim_runtime)
    await sim.start()
    a = sim_runtime.add_node(Managed("map_server"))
    b = sim_runtime.add_node(Managed("planner_server"))
    return sim, a, b


async def test_autostart_brings_the_nodes_up_in_order_and_shutdown_takes_them_down_in_reverse(graph, sim_runtime) -> None:
    sim, a, b = graph
    manager = sim_runtime.add_node(LifecycleManager(parameter_overrides={
        "node_names": ["map_server", "planner_server"], "autostart": True}))
    await _settle(sim, lambda: manager.state is ManagerState.ACTIVE)
    assert LOG == ["configure map_server", "configure planner_server", "activate map_server", "activate planner_server"]
    assert a.current_state is b.current_state is LifecycleState.ACTIVE
    # is_active and manage_nodes, as a client sees them
    from aiorobot.msgs.nav2_msgs import ManageLifecycleNodes
    from aiorobot.msgs.std_srvs import Trigger

    client = sim_runtime.add_node(Navigator("client"))
    is_active = client.create_client(Trigger, "/lifecycle_manager/is_active")
    assert (await is_active.call(Trigger.Request())).success
    LOG.clear()
    manage = client.create_client(ManageLifecycleNodes, "/lifecycle_manager/manage_nodes")
    call = asyncio.ensure_future(manage.call(ManageLifecycleNodes.Request(command=ManageLifecycleNodes.Request.PAUSE)))
    await _settle(sim, call.done)
    assert call.result().success and manager.state is ManagerState.INACTIVE
    assert LOG == ["deactivate planner_server", "deactivate map_server"]
    LOG.clear()
    await _settle(sim, asyncio.ensure_future(client.lifecycleShutdown()).done)
    assert LOG == ["cleanup planner_server", "cleanup map_server", "shutdown planner_server", "shutdown map_server"]
    assert manager.state is ManagerState.FINALIZED and not (await is_active.call(Trigger.Request())).success


async def test_lifecycle_startup_from_the_navigator_and_a_missing_node_fails_the_bringup(graph, sim_runtime) -> None:
    sim, a, b = graph
    manager = sim_runtime.add_node(LifecycleManager(parameter_overrides={
        "node_names": ["map_server", "planner_server"], "bond_timeout": 0.0}))
    nav = sim_runtime.add_node(Navigator())
    await _settle(sim, asyncio.ensure_future(nav.lifecycleStartup()).done)
    assert manager.state is ManagerState.ACTIVE and b.current_state is LifecycleState.ACTIVE
    lonely = sim_runtime.add_node(LifecycleManager("other_manager", parameter_overrides={
        "node_names": ["controller_server"], "service_timeout": 1.0}))
    ok = asyncio.ensure_future(lonely.startup())
    await _settle(sim, ok.done)
    assert ok.result() is False and lonely.state is ManagerState.UNKNOWN


async def test_a_node_that_goes_away_resets_the_others_and_coming_back_brings_them_up(graph, sim_runtime) -> None:
    sim, a, b = graph
    manager = sim_runtime.add_node(LifecycleManager(parameter_overrides={
        "node_names": ["map_server", "planner_server"], "autostart": True, "bond_timeout": 1.0,
        "bond_respawn_max_duration": 30.0}))
    await _settle(sim, lambda: manager.state is ManagerState.ACTIVE)
    LOG.clear()
    b.destroy_node()  # the planner dies
    await _settle(sim, lambda: manager.state is ManagerState.UNCONFIGURED, limit_sec=5.0)
    stats = manager.statistics()
    assert (stats.bond_failures, stats.last_down, stats.state) == (1, "planner_server", ManagerState.UNCONFIGURED)
    assert a.current_state is LifecycleState.UNCONFIGURED  # the others hard-reset
    assert LOG == ["deactivate map_server", "cleanup map_server"]
    respawned = sim_runtime.add_node(Managed("planner_server"))
    await _settle(sim, lambda: manager.state is ManagerState.ACTIVE, limit_sec=10.0)
    assert respawned.current_state is a.current_state is LifecycleState.ACTIVE


def test_node_names_are_required() -> None:
    with pytest.raises(ValueError, match=r"parameter node_names: expected the managed nodes' names in bring-up order, found none"):
        LifecycleManager()
