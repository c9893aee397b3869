"""``aiorobot demo``: the simulated mecanum robot following a waypoint mission.

The simulator's world and robot, AMCL localisation on the world's map, the navigation server
(costmap, A*, Regulated Pure Pursuit, recoveries) and the asyncio BasicNavigator, in one runtime
on sim time (on system time at real-time factor 1, as on a robot); a live progress line, a summary
against ground truth, ``--json`` and ``--plot``. A built-in world named bare has a shipped mission
(:func:`mission_for`); a map YAML path (a Nav2 map) needs waypoints, and its start is checked or
picked by :func:`aiorobot.sim.resolve_start`.
"""

from __future__ import annotations

from ._mission import MISSIONS, DemoSetupError, DemoSummary, mission_for, parse_waypoints, run_demo

__all__ = ["MISSIONS", "DemoSetupError", "DemoSummary", "mission_for", "parse_waypoints", "run_demo"]
