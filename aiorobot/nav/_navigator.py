"""``Navigator``: nav2_simple_commander's BasicNavigator for asyncio.

    nav = Navigator()
    runtime.add_node(nav)
    nav.set_initial_pose(pose_stamped(0, 0, 0))
    await nav.go_to_pose(pose_stamped(2.0, 1.0, 0.0))
    while not nav.is_task_complete():
        print(nav.get_feedback().distance_remaining)
        await asyncio.sleep(0.5)
    assert nav.get_result() is TaskResult.SUCCEEDED

Every method also answers to BasicNavigator's camelCase name (``goToPose``, ``spin``, ``backup``,
``driveOnHeading``, ``followPath``, ``getPathThroughPoses``, ``smoothPath``, ``clearAllCostmaps``,
``getGlobalCostmap``, ``changeMap``, ``waitUntilNav2Active``, ...), for ported scripts.

Tasks (one at a time, as BasicNavigator): navigate to / through poses, follow waypoints, spin,
back up, drive on a heading, follow a path; ``is_task_complete``, ``get_feedback``, ``get_result``
and ``cancel_task`` apply to whichever runs. Queries: a path to a pose or through poses, a smoothed
path, the costmaps; commands: clear the costmaps, change the map, start up or shut down every
lifecycle manager's nodes. Not here: GPS waypoints, routes, docking, following, assisted teleop and
the collision monitor toggle.
"""

from __future__ import annotations

import asyncio
import enum
from typing import Any

from .._core._node import Node

__all__ = ["Navigator", "TaskResult"]


class TaskResult(enum.Enum):
    """nav2_simple_commander's TaskResult."""

    UNKNOWN = 0
    SUCCEEDED = 1
    CANCELED = 2
    FAILED = 3


class Navigator(Node):
    """A client of NavigationServer's (or Nav2's) actions with BasicNavigator's methods.

    rclpy difference: the methods that wait are coroutines (``await nav.go_to_pose(p)``); the
    sync BasicNavigator spins the node inside each call instead.
    """

    def __init__(self, node_name: str = "basic_navigator", namespace: str = "", **kwargs: Any) -> None:
        super().__init__(node_name, namespace=namespace, **kwargs)
        from aiorobot.msgs.geometry_msgs import PoseWithCovarianceStamped
        from aiorobot.msgs.nav2_msgs import (BackUp, ClearEntireCostmap, ComputePathThroughPoses, ComputePathToPose,
                                             DriveOnHeading, FollowPath, FollowWaypoints, GetCostmap, LoadMap,
                                             NavigateThroughPoses, NavigateToPose, SmoothPath, Spin)

        self._to_pose = self.create_action_client(NavigateToPose, "navigate_to_pose")
        self._through = self.create_action_client(NavigateThroughPoses, "navigate_through_poses")
        self._waypoints = self.create_action_client(FollowWaypoints, "follow_waypoints")
        self._path = self.create_action_client(ComputePathToPose, "compute_path_to_pose")
        self._path_through = self.create_action_client(ComputePathThroughPoses, "compute_path_through_poses")
        self._smoother = self.create_action_client(SmoothPath, "smooth_path")
        self._follow_path = self.create_action_client(FollowPath, "follow_path")
        self._spin = self.create_action_client(Spin, "spin")
        self._backup = self.create_action_client(BackUp, "backup")
        self._drive_on_heading = self.create_action_client(DriveOnHeading, "drive_on_heading")
        self._clear = {which: self.create_client(ClearEntireCostmap, f"{which}_costmap/clear_entirely_{which}_costmap")
                       for which in ("global", "local")}
        self._get_costmap = {which: self.create_client(GetCostmap, f"{which}_costmap/get_costmap")
                             for which in ("global", "local")}
        self._load_map = self.create_client(LoadMap, "map_server/load_map")
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

    async def spin(self, spin_dist: float = 1.57, time_allowance: int = 10) -> bool:
        """Turn in place by ``spin_dist`` (rad, + counter-clockwise) within ``time_allowance`` (s): the Spin behaviour."""
        from aiorobot import Duration
        from aiorobot.msgs.nav2_msgs import Spin

        goal = Spin.Goal(target_yaw=float(spin_dist), time_allowance=Duration(seconds=time_allowance).to_msg())
        return await self._send(self._spin, goal)

    async def backup(self, backup_dist: float = 0.15, backup_speed: float = 0.025, time_allowance: int = 10) -> bool:
        """Drive ``backup_dist`` (m) backwards at ``backup_speed`` (m/s): the BackUp behaviour."""
        from aiorobot import Duration
        from aiorobot.msgs.geometry_msgs import Point
        from aiorobot.msgs.nav2_msgs import BackUp

        goal = BackUp.Goal(target=Point(x=float(backup_dist)), speed=float(backup_speed),
                           time_allowance=Duration(seconds=time_allowance).to_msg())
        return await self._send(self._backup, goal)

    async def drive_on_heading(self, dist: float = 0.15, speed: float = 0.025, time_allowance: int = 10) -> bool:
        """Drive ``dist`` (m) straight on at ``speed`` (m/s; both negative: backwards): the DriveOnHeading behaviour."""
        from aiorobot import Duration
        from aiorobot.msgs.geometry_msgs import Point
        from aiorobot.msgs.nav2_msgs import DriveOnHeading

        goal = DriveOnHeading.Goal(target=Point(x=float(dist)), speed=float(speed),
                                   time_allowance=Duration(seconds=time_allowance).to_msg())
        return await self._send(self._drive_on_heading, goal)

    async def follow_path(self, path: Any, controller_id: str = "", goal_checker_id: str = "",
                          progress_checker_id: str = "") -> bool:
        """Follow ``path`` (nav_msgs/Path) with the controller, no planning: controller_server's FollowPath."""
        from aiorobot.msgs.nav2_msgs import FollowPath

        return await self._send(self._follow_path, FollowPath.Goal(path=path, controller_id=controller_id,
                                                                   goal_checker_id=goal_checker_id,
                                                                   progress_checker_id=progress_checker_id))

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
        from aiorobot.msgs.nav2_msgs import ComputePathToPose

        result = await self._query(self._path, ComputePathToPose.Goal(start=start, goal=goal, planner_id=planner_id,
                                                                      use_start=use_start), "get_path")
        return None if result is None else result.path

    async def get_path_through_poses(self, start: Any, goals: list[Any], planner_id: str = "", use_start: bool = False) -> Any:
        """The planned nav_msgs/Path from ``start`` (or the robot) through ``goals`` in turn; None when there is none."""
        from aiorobot.msgs.nav2_msgs import ComputePathThroughPoses

        goal = ComputePathThroughPoses.Goal(goals=list(goals), start=start, planner_id=planner_id, use_start=use_start)
        result = await self._query(self._path_through, goal, "get_path_through_poses")
        return None if result is None else result.path

    async def smooth_path(self, path: Any, smoother_id: str = "", max_duration: float = 2.0,
                          check_for_collisions: bool = False) -> Any:
        """``path`` smoothed by the smoother server (nav_msgs/Path); None when it fails."""
        from aiorobot import Duration
        from aiorobot.msgs.nav2_msgs import SmoothPath

        goal = SmoothPath.Goal(path=path, smoother_id=smoother_id, max_smoothing_duration=Duration(seconds=max_duration).to_msg(),
                               check_for_collisions=check_for_collisions)
        result = await self._query(self._smoother, goal, "smooth_path")
        return None if result is None else result.path

    async def _query(self, client: Any, goal: Any, what: str, timeout_sec: float = 10.0) -> Any:
        """Send a one-shot action goal (not a task) and wait for its result; None with one line on failure."""
        from aiorobot import GoalStatus

        if not await client.wait_for_server(timeout_sec=timeout_sec):
            self.get_logger().error(f"{what}: no action server {client!r} within {timeout_sec:g} s")
            return None
        handle = await client.send_goal(goal)
        if not handle.accepted:
            self.get_logger().error(f"{what}: goal rejected")
            return None
        result = await handle.result()
        if handle.status is not GoalStatus.SUCCEEDED:
            self.get_logger().warning(f"{what} failed: {result.error_msg}")
            return None
        return result

    # -- costmaps and maps --------------------------------------------------------------

    async def clear_all_costmaps(self) -> None:
        """Clear the global and the local costmap (their obstacle layers)."""
        await self.clear_local_costmap()
        await self.clear_global_costmap()

    async def clear_local_costmap(self) -> None:
        await self._call(self._clear["local"], "clear_local_costmap")

    async def clear_global_costmap(self) -> None:
        await self._call(self._clear["global"], "clear_global_costmap")

    async def get_global_costmap(self) -> Any:
        """The global costmap (nav2_msgs/Costmap); None when the service does not answer."""
        response = await self._call(self._get_costmap["global"], "get_global_costmap")
        return None if response is None else response.map

    async def get_local_costmap(self) -> Any:
        """The local costmap (nav2_msgs/Costmap); None when the service does not answer."""
        response = await self._call(self._get_costmap["local"], "get_local_costmap")
        return None if response is None else response.map

    async def change_map(self, map_filepath: str) -> bool:
        """Load ``map_filepath`` (a map_server YAML) into the map server, which publishes it on /map."""
        from aiorobot.msgs.nav2_msgs import LoadMap

        response = await self._call(self._load_map, "change_map", LoadMap.Request(map_url=str(map_filepath)))
        if response is None:
            return False
        if response.result != LoadMap.Response.RESULT_SUCCESS:
            self.get_logger().error(f"change_map: the map server refused {map_filepath!r} (LoadMap result {response.result})")
            return False
        return True

    async def _call(self, client: Any, what: str, request: Any = None, timeout_sec: float = 10.0) -> Any:
        if not await client.wait_for_service(timeout_sec=timeout_sec):
            self.get_logger().error(f"{what}: no service {client.srv_name} within {timeout_sec:g} s")
            return None
        return await client.call(request if request is not None else client.srv_type.Request())

    # -- start-up ---------------------------------------------------------------------------

    async def lifecycle_startup(self) -> None:
        """STARTUP on every lifecycle manager in the graph (each ``*/manage_nodes`` service), as BasicNavigator."""
        await self._manage_all("STARTUP")

    async def lifecycle_shutdown(self) -> None:
        """SHUTDOWN on every lifecycle manager in the graph."""
        await self._manage_all("SHUTDOWN")

    async def _manage_all(self, command: str) -> None:
        from aiorobot.msgs.nav2_msgs import ManageLifecycleNodes

        found = [name for name, types in self.get_service_names_and_types()
                 if "nav2_msgs/srv/ManageLifecycleNodes" in types]
        if not found:
            self.get_logger().warning(f"lifecycle {command.lower()}: no lifecycle manager (ManageLifecycleNodes service) "
                                      "in the graph")
        for name in found:
            self.get_logger().info(f"{command} on {name}")
            client = self.create_client(ManageLifecycleNodes, name)
            try:
                response = await self._call(client, name, ManageLifecycleNodes.Request(
                    command=getattr(ManageLifecycleNodes.Request, command)))
                if response is not None and not response.success:
                    self.get_logger().error(f"{name}: {command} failed")
            finally:
                self.destroy_client(client)

    async def wait_until_nav2_active(self, navigator: str = "bt_navigator", localizer: str = "amcl",
                                     timeout_sec: float | None = None) -> None:
        """Wait until navigation can take goals: the navigate_to_pose server is up and, with ``localizer``
        ``amcl``, a pose estimate has arrived on amcl_pose (as BasicNavigator waits for AMCL's first pose).

        ``navigator`` is accepted for BasicNavigator's signature: aiorobot's navigation nodes are not
        lifecycle nodes, so the action server's presence is what "active" means.
        """
        from aiorobot.msgs.geometry_msgs import PoseWithCovarianceStamped

        async def ready() -> None:
            while not await self._to_pose.wait_for_server(timeout_sec=1.0):
                self.get_logger().info(f"waiting for {navigator}'s navigate_to_pose action server ...")
            if localizer == "amcl":
                got = asyncio.Event()
                sub = self.create_subscription(PoseWithCovarianceStamped, "amcl_pose", lambda _m: got.set(), 10)
                try:
                    await got.wait()
                finally:
                    self.destroy_subscription(sub)

        await asyncio.wait_for(ready(), timeout_sec)
        self.get_logger().info("Nav2 is ready for use!")

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
    getPathThroughPoses = get_path_through_poses  # noqa: N815
    smoothPath = smooth_path  # noqa: N815
    driveOnHeading = drive_on_heading  # noqa: N815
    followPath = follow_path  # noqa: N815
    clearAllCostmaps = clear_all_costmaps  # noqa: N815
    clearLocalCostmap = clear_local_costmap  # noqa: N815
    clearGlobalCostmap = clear_global_costmap  # noqa: N815
    getGlobalCostmap = get_global_costmap  # noqa: N815
    getLocalCostmap = get_local_costmap  # noqa: N815
    changeMap = change_map  # noqa: N815
    waitUntilNav2Active = wait_until_nav2_active  # noqa: N815
    lifecycleStartup = lifecycle_startup  # noqa: N815
    lifecycleShutdown = lifecycle_shutdown  # noqa: N815
