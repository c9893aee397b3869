"""Goal preemption for the navigation server's navigate_to_pose, navigate_through_poses and
follow_waypoints, as Nav2's.

Nav2's bt_navigator and waypoint_follower serve each with nav2_util's SimpleActionServer: a new
goal for the action that is running is accepted and replaces the running one, which ends ABORTED
with an empty result (``accept_pending_goal``); a goal for another navigation action while one runs is refused, as is
(here) a new goal asking for another behaviour tree than the running goal's.

:meth:`GoalPreemption.begin`, called by a goal's execute before it drives, cancels the task of every
older goal of the server's and waits for it to end (its ``finally`` stops the base): the action
server ends a goal whose task is cancelled ABORTED with an empty result, Nav2's ending.

rclpy / Nav2 difference: a goal for another tree is rejected by the goal callback; Nav2 accepts it,
then aborts it ("Preemption request was rejected since the requested BT XML file is not the same
as the one that the current goal is executing").
"""

from __future__ import annotations

import asyncio
from typing import Any

__all__ = ["GoalPreemption"]


class GoalPreemption:
    """The running goals of a node's navigation actions, and whether a new goal may replace them.

    ``preemptible``: the goal types a newer goal of the same type replaces.
    """

    def __init__(self, node: Any, preemptible: tuple[type, ...]) -> None:
        self._node = node
        self._preemptible = preemptible
        self._running: dict[asyncio.Task[Any], Any] = {}

    def __repr__(self) -> str:
        return f"<GoalPreemption of {self._node.get_name()} running={list(self._running.values())}>"

    def preempts(self, goal: Any) -> bool:
        """Whether ``goal`` may replace the running goals (all of its type, with the same tree)."""
        if not self._running:
            return False
        if type(goal) not in self._preemptible:
            return False
        for handle in self._running.values():
            if type(handle.request) is not type(goal):
                return False
            if getattr(handle.request, "behavior_tree", "") != getattr(goal, "behavior_tree", ""):
                self._node.get_logger().warning(
                    f"a goal for behaviour tree {goal.behavior_tree!r} cannot preempt the running goal's "
                    f"({handle.request.behavior_tree!r}); rejected, as Nav2 refuses it")
                return False
        return True

    async def begin(self, handle: Any) -> None:
        """Register the calling goal's task; end every older goal (ABORTED) and wait until each has."""
        task = asyncio.current_task()
        assert task is not None
        older = [t for t in self._running if not t.done()]
        self._running[task] = handle
        for t in older:
            self._node.get_logger().info(f"{self._running[t]!r} preempted by {handle!r}: it ends aborted, as Nav2's")
            t.cancel()
        try:
            if older:
                await asyncio.wait(older)
        except BaseException:
            self._running.pop(task, None)
            raise

    def end(self) -> None:
        """The calling goal has finished."""
        task = asyncio.current_task()
        if task is not None:
            self._running.pop(task, None)
