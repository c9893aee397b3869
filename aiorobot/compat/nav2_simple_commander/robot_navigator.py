"""``nav2_simple_commander.robot_navigator`` for rclpy programs run on aiorobot (``aiorobot exec``).

:class:`BasicNavigator` is a synchronous rclpy node with Nav2's BasicNavigator methods, written on
aiorobot's rclpy layer: each call sends its goal or request and spins until it is answered, and
``isTaskComplete`` spins for up to 0.1 s, as Nav2's does; feedback and results are the nav2_msgs
ones. It talks to aiorobot's NavigationServer, map server and lifecycle managers, or to Nav2.

Differences: ``waitUntilNav2Active`` waits for the ``navigate_to_pose`` action server (and, with
the ``amcl`` localizer, for a pose on ``amcl_pose``, re-publishing the initial pose meanwhile)
instead of asking lifecycle nodes for their state, since aiorobot's navigation server is not one;
GPS waypoints, routes, docking, following and assisted teleop are not provided.
"""

from __future__ import annotations

import enum
from typing import Any

from aiorobot.compat.rclpy.action import ActionClient
from aiorobot.compat.rclpy.duration import Duration
from aiorobot.compat.rclpy.node import Node

__all__ = ["BasicNavigator", "RunningTask", "TaskResult"]

_SUCCEEDED, _CANCELED, _ABORTED = 4, 5, 6  # action_msgs/GoalStatus


class TaskResult(enum.Enum):
    UNKNOWN = 0
    SUCCEEDED = 1
    CANCELED = 2
    FAILED = 3


class RunningTask(enum.Enum):
    NONE = 0
    NAVIGATE_TO_POSE = 1
    NAVIGATE_THROUGH_POSES = 2
    FOLLOW_PATH = 3
    FOLLOW_WAYPOINTS = 4
    SPIN = 6
    BACKUP = 7
    DRIVE_ON_HEADING = 8


def _spin_until(node: Any, future: Any, timeout_sec: float | None = None) -> None:
    import aiorobot.compat.rclpy as rclpy

    rclpy.spin_until_future_complete(node, future, timeout_sec=timeout_sec)


class BasicNavigator(Node):
    """Nav2's BasicNavigator (see the module doc for what differs)."""

    def __init__(self, node_name: str = "basic_navigator", namespace: str = "") -> None:
        super().__init__(node_name=node_name, namespace=namespace)
        from aiorobot.msgs.geometry_msgs import PoseWithCovarianceStamped
        from aiorobot.msgs.nav2_msgs import (BackUp, ClearEntireCostmap, ComputePathThroughPoses, ComputePathToPose,
                                             DriveOnHeading, FollowPath, FollowWaypoints, GetCostmap, LoadMap,
                                             NavigateThroughPoses, NavigateToPose, SmoothPath, Spin)

        self.initial_pose = None
        self.goal_handle: Any = None
        self.result_future: Any = None
        self.feedback: Any = None
        self.status: int | None = None
        self.error_code, self.error_msg = 0, ""
        self.initial_pose_received = False
        self._actions = {
            "to_pose": ActionClient(self, NavigateToPose, "navigate_to_pose"),
            "through": ActionClient(self, NavigateThroughPoses, "navigate_through_poses"),
            "waypoints": ActionClient(self, FollowWaypoints, "follow_waypoints"),
            "follow_path": ActionClient(self, FollowPath, "follow_path"),
            "path": ActionClient(self, ComputePathToPose, "compute_path_to_pose"),
            "path_through": ActionClient(self, ComputePathThroughPoses, "compute_path_through_poses"),
            "smooth": ActionClient(self, SmoothPath, "smooth_path"),
            "spin": ActionClient(self, Spin, "spin"),
            "backup": ActionClient(self, BackUp, "backup"),
            "drive": ActionClient(self, DriveOnHeading, "drive_on_heading"),
        }
        self._clear = {w: self.create_client(ClearEntireCostmap, f"{w}_costmap/clear_entirely_{w}_costmap")
                       for w in ("global", "local")}
        self._get_costmap = {w: self.create_client(GetCostmap, f"{w}_costmap/get_costmap") for w in ("global", "local")}
        self._load_map = self.create_client(LoadMap, "map_server/load_map")
        self.create_subscription(PoseWithCovarianceStamped, "amcl_pose", self._amcl_pose, 10)
        self._initial_pub = self.create_publisher(PoseWithCovarianceStamped, "initialpose", 10)

    def destroyNode(self) -> None:  # noqa: N802
        self.destroy_node()

    # -- tasks ------------------------------------------------------------------------------------

    def _task(self, key: str, goal: Any, what: str, task: RunningTask) -> RunningTask | None:
        self.clearPreviousState()
        client = self._actions[key]
        while not client.wait_for_server(timeout_sec=1.0):
            self.info(f"'{client.action_name}' action server not available, waiting...")
        future = client.send_goal_async(goal, self._feedback_callback)
        _spin_until(self, future)
        self.goal_handle = future.result()
        if not self.goal_handle or not self.goal_handle.accepted:
            self.setTaskError(int(getattr(client.action_type.Result, "UNKNOWN", 0)), f"{what} request was rejected!")
            self.error(f"{what} request was rejected!")
            return None
        self.result_future = self.goal_handle.get_result_async()
        return task

    def goToPose(self, pose: Any, behavior_tree: str = "") -> RunningTask | None:  # noqa: N802
        from aiorobot.msgs.nav2_msgs import NavigateToPose

        self.info(f"Navigating to goal: {pose.pose.position.x} {pose.pose.position.y}...")
        return self._task("to_pose", NavigateToPose.Goal(pose=pose, behavior_tree=behavior_tree), "Goal",
                          RunningTask.NAVIGATE_TO_POSE)

    def goThroughPoses(self, poses: Any, behavior_tree: str = "") -> RunningTask | None:  # noqa: N802
        from aiorobot.msgs.nav2_msgs import NavigateThroughPoses

        poses = list(getattr(poses, "goals", poses))
        self.info(f"Navigating with {len(poses)} goals....")
        return self._task("through", NavigateThroughPoses.Goal(poses=poses, behavior_tree=behavior_tree), "Goal",
                          RunningTask.NAVIGATE_THROUGH_POSES)

    def followWaypoints(self, poses: list[Any]) -> RunningTask | None:  # noqa: N802
        from aiorobot.msgs.nav2_msgs import FollowWaypoints

        self.info(f"Following {len(poses)} goals....")
        return self._task("waypoints", FollowWaypoints.Goal(poses=list(poses)), "Following", RunningTask.FOLLOW_WAYPOINTS)

    def followPath(self, path: Any, controller_id: str = "", goal_checker_id: str = "",  # noqa: N802
                   progress_checker_id: str = "") -> RunningTask | None:
        from aiorobot.msgs.nav2_msgs import FollowPath

        self.info("Executing path...")
        goal = FollowPath.Goal(path=path, controller_id=controller_id, goal_checker_id=goal_checker_id,
                               progress_checker_id=progress_checker_id)
        return self._task("follow_path", goal, "FollowPath goal", RunningTask.FOLLOW_PATH)

    def spin(self, spin_dist: float = 1.57, time_allowance: int = 10) -> RunningTask | None:
        from aiorobot.msgs.nav2_msgs import Spin

        self.info(f"Spinning to angle {spin_dist}....")
        goal = Spin.Goal(target_yaw=float(spin_dist), time_allowance=Duration(seconds=time_allowance).to_msg())
        return self._task("spin", goal, "Spin", RunningTask.SPIN)

    def backup(self, backup_dist: float = 0.15, backup_speed: float = 0.025, time_allowance: int = 10) -> RunningTask | None:
        from aiorobot.msgs.geometry_msgs import Point
        from aiorobot.msgs.nav2_msgs import BackUp

        self.info(f"Backing up {backup_dist} m at {backup_speed} m/s....")
        goal = BackUp.Goal(target=Point(x=float(backup_dist)), speed=float(backup_speed),
                           time_allowance=Duration(seconds=time_allowance).to_msg())
        return self._task("backup", goal, "Backup", RunningTask.BACKUP)

    def driveOnHeading(self, dist: float = 0.15, speed: float = 0.025, time_allowance: int = 10) -> RunningTask | None:  # noqa: N802
        from aiorobot.msgs.geometry_msgs import Point
        from aiorobot.msgs.nav2_msgs import DriveOnHeading

        self.info(f"Drive {dist} m on heading at {speed} m/s....")
        goal = DriveOnHeading.Goal(target=Point(x=float(dist)), speed=float(speed),
                                   time_allowance=Duration(seconds=time_allowance).to_msg())
        return self._task("drive", goal, "Drive On Heading", RunningTask.DRIVE_ON_HEADING)

    def cancelTask(self) -> None:  # noqa: N802
        self.info("Canceling current task.")
        if self.result_future is not None and self.goal_handle is not None:
            _spin_until(self, self.goal_handle.cancel_goal_async())

    def isTaskComplete(self, task: RunningTask = RunningTask.NONE) -> bool:  # noqa: N802
        if self.result_future is None:
            return True
        _spin_until(self, self.result_future, timeout_sec=0.10)
        if not self.result_future.done():
            return False
        response = self.result_future.result()
        self.status = int(response.status)
        if self.status != _SUCCEEDED:
            result = response.result
            self.setTaskError(int(getattr(result, "error_code", 0)), str(getattr(result, "error_msg", "")))
            self.debug(f"Task failed with status code: {self.status}")
        return True

    def getFeedback(self, task: RunningTask = RunningTask.NONE) -> Any:  # noqa: N802
        return self.feedback

    def getResult(self) -> TaskResult:  # noqa: N802
        return {_SUCCEEDED: TaskResult.SUCCEEDED, _ABORTED: TaskResult.FAILED,
                _CANCELED: TaskResult.CANCELED}.get(self.status, TaskResult.UNKNOWN)  # type: ignore[arg-type]

    def clearPreviousState(self) -> None:  # noqa: N802
        self.feedback = None
        self.status = None
        self.error_code, self.error_msg = 0, ""

    def setTaskError(self, error_code: int, error_msg: str) -> None:  # noqa: N802
        self.error_code, self.error_msg = error_code, error_msg

    def getTaskError(self) -> tuple[int, str]:  # noqa: N802
        return self.error_code, self.error_msg

    def _feedback_callback(self, msg: Any) -> None:
        self.feedback = getattr(msg, "feedback", msg)

    # -- pose, start-up -----------------------------------------------------------------------------

    def setInitialPose(self, initial_pose: Any) -> None:  # noqa: N802
        self.initial_pose_received = False
        self.initial_pose = initial_pose
        self._publish_initial_pose()

    def _publish_initial_pose(self) -> None:
        from aiorobot.msgs.geometry_msgs import PoseWithCovarianceStamped

        msg = PoseWithCovarianceStamped()
        msg.pose.pose = self.initial_pose.pose
        msg.header.frame_id = self.initial_pose.header.frame_id
        msg.header.stamp = self.initial_pose.header.stamp
        self.info("Publishing Initial Pose")
        self._initial_pub.publish(msg)

    def _amcl_pose(self, _msg: Any) -> None:
        self.initial_pose_received = True

    def waitUntilNav2Active(self, navigator: str = "bt_navigator", localizer: str = "amcl") -> None:  # noqa: N802
        import aiorobot.compat.rclpy as rclpy

        if localizer == "amcl":
            self.info("Setting initial pose")
            while not self.initial_pose_received:
                if self.initial_pose is not None:
                    self._publish_initial_pose()
                self.info("Waiting for amcl_pose to be received")
                rclpy.spin_once(self, timeout_sec=1.0)
        while not self._actions["to_pose"].wait_for_server(timeout_sec=1.0):
            self.info(f"{navigator}'s navigate_to_pose not available, waiting...")
        self.info("Nav2 is ready for use!")

    def lifecycleStartup(self) -> None:  # noqa: N802
        self._manage("STARTUP")

    def lifecycleShutdown(self) -> None:  # noqa: N802
        self._manage("SHUTDOWN")

    def _manage(self, command: str) -> None:
        from aiorobot.msgs.nav2_msgs import ManageLifecycleNodes

        self.info(f"{command.capitalize()} of the managed nodes...")
        for name, types in self.get_service_names_and_types():
            if "nav2_msgs/srv/ManageLifecycleNodes" not in types:
                continue
            client = self.create_client(ManageLifecycleNodes, name)
            while not client.wait_for_service(timeout_sec=1.0):
                self.info(f"{name} service not available, waiting...")
            future = client.call_async(ManageLifecycleNodes.Request(command=getattr(ManageLifecycleNodes.Request, command)))
            _spin_until(self, future)
            self.destroy_client(client)

    # -- queries --------------------------------------------------------------------------------------

    def _query(self, key: str, goal: Any, what: str) -> Any:
        client = self._actions[key]
        while not client.wait_for_server(timeout_sec=1.0):
            self.info(f"'{client.action_name}' action server not available, waiting...")
        future = client.send_goal_async(goal)
        _spin_until(self, future)
        handle = future.result()
        if not handle or not handle.accepted:
            self.error(f"{what} request was rejected!")
            return None
        result_future = handle.get_result_async()
        _spin_until(self, result_future)
        response = result_future.result()
        if int(response.status) != _SUCCEEDED:
            self.setTaskError(int(response.result.error_code), str(response.result.error_msg))
            self.warn(f"{what} failed with status code: {response.status}")
            return None
        return response.result

    def getPath(self, start: Any, goal: Any, planner_id: str = "", use_start: bool = False) -> Any:  # noqa: N802
        from aiorobot.msgs.nav2_msgs import ComputePathToPose

        result = self._query("path", ComputePathToPose.Goal(start=start, goal=goal, planner_id=planner_id,
                                                            use_start=use_start), "Get path")
        return None if result is None else result.path

    def getPathThroughPoses(self, start: Any, goals: Any, planner_id: str = "", use_start: bool = False) -> Any:  # noqa: N802
        from aiorobot.msgs.nav2_msgs import ComputePathThroughPoses

        goal = ComputePathThroughPoses.Goal(goals=list(getattr(goals, "goals", goals)), start=start,
                                            planner_id=planner_id, use_start=use_start)
        result = self._query("path_through", goal, "Get path through poses")
        return None if result is None else result.path

    def smoothPath(self, path: Any, smoother_id: str = "", max_duration: float = 2.0,  # noqa: N802
                   check_for_collision: bool = False) -> Any:
        from aiorobot.msgs.nav2_msgs import SmoothPath

        goal = SmoothPath.Goal(path=path, smoother_id=smoother_id, max_smoothing_duration=Duration(seconds=max_duration).to_msg(),
                               check_for_collisions=check_for_collision)
        result = self._query("smooth", goal, "Smooth path")
        return None if result is None else result.path

    def _call(self, client: Any, request: Any) -> Any:
        while not client.wait_for_service(timeout_sec=1.0):
            self.info(f"{client.srv_name} service not available, waiting...")
        future = client.call_async(request)
        _spin_until(self, future)
        return future.result()

    def changeMap(self, map_filepath: str) -> bool:  # noqa: N802
        from aiorobot.msgs.nav2_msgs import LoadMap

        response = self._call(self._load_map, LoadMap.Request(map_url=map_filepath))
        if response is None or response.result != LoadMap.Response.RESULT_SUCCESS:
            self.error("Change map request failed!")
            return False
        self.info("Change map request was successful!")
        return True

    def clearAllCostmaps(self) -> None:  # noqa: N802
        self.clearLocalCostmap()
        self.clearGlobalCostmap()

    def clearLocalCostmap(self) -> None:  # noqa: N802
        self._call(self._clear["local"], self._clear["local"].srv_type.Request())

    def clearGlobalCostmap(self) -> None:  # noqa: N802
        self._call(self._clear["global"], self._clear["global"].srv_type.Request())

    def getGlobalCostmap(self) -> Any:  # noqa: N802
        return self._call(self._get_costmap["global"], self._get_costmap["global"].srv_type.Request()).map

    def getLocalCostmap(self) -> Any:  # noqa: N802
        return self._call(self._get_costmap["local"], self._get_costmap["local"].srv_type.Request()).map

    # -- logging --------------------------------------------------------------------------------------

    def info(self, msg: str) -> None:
        self.get_logger().info(msg)

    def warn(self, msg: str) -> None:
        self.get_logger().warning(msg)

    def error(self, msg: str) -> None:
        self.get_logger().error(msg)

    def debug(self, msg: str) -> None:
        self.get_logger().debug(msg)

