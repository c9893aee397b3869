"""Navigator.lifecycleStartup / lifecycleShutdown as BasicNavigator's: every lifecycle manager in the
graph is asked to STARTUP / SHUTDOWN over its ~/manage_nodes service."""

from __future__ import annotations

import logging

from aiorobot.lifecycle import LifecycleState
from aiorobot.nav import LifecycleManager, Navigator

from .test_lifecycle_manager import Managed


async def test_lifecycle_startup_and_shutdown_go_through_every_manager(runtime):
    journal: list[tuple[str, str]] = []
    nav_nodes = [runtime.add_node(Managed(n, journal)) for n in ("controller_server", "bt_navigator")]
    loc_nodes = [runtime.add_node(Managed(n, journal)) for n in ("map_server", "amcl")]
    runtime.add_node(LifecycleManager("lifecycle_manager_navigation", parameter_overrides={
        "node_names": ["controller_server", "bt_navigator"], "bond_timeout": 0.0}))
    runtime.add_node(LifecycleManager("lifecycle_manager_localization", parameter_overrides={
        "node_names": ["map_server", "amcl"], "bond_timeout": 0.0}))
    nav = runtime.add_node(Navigator())
    assert await nav.lifecycleStartup(timeout_sec=10.0)
    assert [n.current_state for n in nav_nodes + loc_nodes] == [LifecycleState.ACTIVE] * 4
    assert sorted(journal) == sorted([(h, n) for h in ("configure", "activate")
                                      for n in ("controller_server", "bt_navigator", "map_server", "amcl")])
    assert await nav.lifecycleShutdown(timeout_sec=10.0)
    assert [n.current_state for n in nav_nodes + loc_nodes] == [LifecycleState.FINALIZED] * 4


async def test_lifecycle_startup_reports_a_failed_manager_and_no_manager(runtime, caplog):
    nav = runtime.add_node(Navigator())
    with caplog.at_level(logging.WARNING):
        assert not await nav.lifecycle_startup()
    assert ("Starting up: no lifecycle manager in the graph (no nav2_msgs/srv/ManageLifecycleNodes service)"
            in caplog.messages)
    runtime.add_node(Managed("amcl", [], fail="activate"))
    runtime.add_node(LifecycleManager(parameter_overrides={"node_names": ["amcl"], "bond_timeout": 0.0}))
    with caplog.at_level(logging.ERROR):
        assert not await nav.lifecycle_startup(timeout_sec=10.0)
    assert ("Starting up: /lifecycle_manager/manage_nodes reported failure (see its log for the node and why)"
            in caplog.messages)
