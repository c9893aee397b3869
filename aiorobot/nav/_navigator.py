"""``Navigator``: nav2_simple_commander's BasicNavigator for asyncio.

    nav = Navigator()
    runtime.add_node(nav)
    nav.set_initial_pose(pose_stamped(0, 0, 0))
    await nav.go_to_pose(pose_stamped(2.0, 1.0, 0.0))
    while not nav.is_task_complete():
        print(nav.get_feedback().distance_remaining)
        await asyncio.sleep(0.5)
    assert nav.get_result() is TaskResult.SUCCEEDED

``goToPose``, ``followWaypoints``, ``goThroughPoses``, ``isTaskComplete``, ``getFeedback``,
``getResult``, ``cancelTask``, ``setInitialPose`` and ``getPath`` are the same methods under
BasicNavigator's camelCase names, for ported scripts.
"""

from __future__ import annotations

import asyncio
import enum
from typing import Any

from .._core._node import Node
from ._navigator_lifecycle import LifecycleCommands

__all__ = ["Navigator", "TaskResult"]


class TaskResult(enum.Enum):
    """nav2_simple_commander's TaskResult."""

    UNKNOWN = 0
    SUCCEEDED = 1
    CANCELED = 2
    FAILED = 3


class Navigator(LifecycleCommands, Node):
    """A client of NavigationServer's (or Nav2's) actions with BasicNavigator's methods.

    rclpy difference: the methods that wait are coroutines (``await nav.go_to_pose(p)``); the
    sync BasicNavigator spins the node inside each call instead.
    """

    def __init__(self, node_name: str = "basic_navigator", namespace: str = "", **kwargs: Any) -> None:
        super().__init__(node_name, namespace=namespace, **kwargs)
        from aiorobot.msgs.geometry_msgs import PoseWithCovarianceStamped
        from aiorobot.msgs.nav2_msgs import ComputePathToPose, FollowWaypoints, NavigateThroughPoses, NavigateToPose

        self._to_pose = self.create_action_client(NavigateToPose, "navigate_to_pose")
        self._through = self.create_action_client(NavigateThroughPoses, "navigate_through_poses")
        self._waypoints = self.create_action_client(FollowWaypoints, "follow_waypoints")
        self._path = self.create_action_client(ComputePathToPose, "compute_path_to_pose")
        self._initial = self.create_publisher(PoseWithCovarianceStamped, "/initialpose", 10)
        self._handle: Any = None
        self._feedback: Any = None
        self._result_task: asyncio.Task[Any] | None = None
        self._feedback_task: asyncio.Task[Any] | None = None
        self.result: Any = None
        self.status: Any = None

    # -- tasks --------------------------------------------------------------------------

    async def go_to_pose(self, pose: Any, behavior_tree: str = "") -> bool:
        from aiorobot.msgs.nav2_msgs import NavigateToPose

        return await self._send(self._to_pose, NavigateToPose.Goal(pose=pose, behavior_tree=behavior_tree))

    async def go_through_poses(self, poses: list[Any], behavior_tree: str = "") -> bool:
        from aiorobot.msgs.nav2_msgs import NavigateThroughPoses

        return await self._send(self._through, NavigateThroughPoses.Goal(poses=list(poses), behavior_tree=behavior_tree))

    async def follow_waypoints(self, poses: list[Any]) -> bool:
        from aiorobot.msgs.nav2_msgs import FollowWaypoints

        return await self._send(self._waypoints, FollowWaypoints.Goal(poses=list(poses)))

    async def _send(self, client: Any, goal: Any, timeout_sec: float = 10.0) -> bool:
        # A goal sent while a task runs becomes the task, as in BasicNavigator: the server preempts
        # the running goal (navigate_to_pose: it ends aborted) or refuses the new one.
        if not await client.wait_for_server(timeout_sec=timeout_sec):
            self.get_logger().error(f"{client!r}: no action server within {timeout_sec:g} s")
            return False
        handle = await client.send_goal(goal, feedback_callback=self._on_feedback)
        if not handle.accepted:
            self.get_logger().error("goal rejected")
            return False
        self.result = self.status = self._feedback = None
        self._handle = handle
        self._result_task = self.create_task(self._wait_result(handle))
        return True

    def _on_feedback(self, msg: Any) -> None:
        self._feedback = getattr(msg, "feedback", msg)

    async def _wait_result(self, handle: Any) -> None:
        result = await handle.result()
        if handle is self._handle:  # not a goal a newer one replaced
            self.result, self.status = result, handle.status

    def is_task_complete(self) -> bool:
        """True when the last task ended (or none was sent)."""
        return self._result_task is None or self._result_task.done()

    async def wait_for_task(self, timeout_sec: float | None = None) -> TaskResult:
        """Wait until the running task ends; its TaskResult."""
        if self._result_task is not None:
            await asyncio.wait_for(asyncio.shield(self._result_task), timeout_sec)
        return self.get_result()

    def get_feedback(self) -> Any:
        return self._feedback

    def get_result(self) -> TaskResult:
        from aiorobot import GoalStatus

        if self.status is None:
            return TaskResult.UNKNOWN
        return {GoalStatus.SUCCEEDED: TaskResult.SUCCEEDED, GoalStatus.CANCELED: TaskResult.CANCELED,
                GoalStatus.ABORTED: TaskResult.FAILED}.get(self.status, TaskResult.UNKNOWN)

    async def cancel_task(self) -> None:
        if self._handle is not None and not self.is_task_complete():
            await self._handle.cancel()
            await self.wait_for_task()

    # -- pose and path ------------------------------------------------------------------

    def set_initial_pose(self, pose: Any) -> None:
        """Publish ``pose`` (PoseStamped) on /initialpose for AMCL."""
        from aiorobot.msgs.geometry_msgs import PoseWithCovarianceStamped

        msg = PoseWithCovarianceStamped()
        msg.header = pose.header
        msg.pose.pose = pose.pose
        cov = [0.0] * 36
        cov[0] = cov[7] = 0.25
        cov[35] = 0.0685
        msg.pose.covariance = cov
        self._initial.publish(msg)

    async def get_path(self, start: Any, goal: Any, planner_id: str = "", use_start: bool = False) -> Any:
        """The planned nav_msgs/Path from ``start`` (or the robot) to ``goal``; None when there is none."""
        from aiorobot import GoalStatus
        from aiorobot.msgs.nav2_msgs import ComputePathToPose

        if not await self._path.wait_for_server(timeout_sec=10.0):
            return None
        handle = await self._path.send_goal(ComputePathToPose.Goal(start=start, goal=goal, planner_id=planner_id, use_start=use_start))
        if not handle.accepted:
            return None
        result = await handle.result()
        if handle.status is not GoalStatus.SUCCEEDED:
            self.get_logger().warning(f"get_path failed: {result.error_msg}")
            return None
        return result.path

    # BasicNavigator's names
    goToPose = go_to_pose  # noqa: N815
    goThroughPoses = go_through_poses  # noqa: N815
    followWaypoints = follow_waypoints  # noqa: N815
    isTaskComplete = is_task_complete  # noqa: N815
    getFeedback = get_feedback  # noqa: N815
    getResult = get_result  # noqa: N815
    cancelTask = cancel_task  # noqa: N815
    setInitialPose = set_initial_pose  # noqa: N815
    getPath = get_path  # noqa: N815
