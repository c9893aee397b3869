"""``nav2_simple_commander.robot_navigator`` on aiorobot: the blocking ``BasicNavigator`` of Nav2's
example programs, over the asyncio :class:`aiorobot.nav.Navigator`.

``BasicNavigator`` is an rclpy node (``get_clock()``, ``get_logger()``, ...) that is also the
asyncio Navigator: each of BasicNavigator's methods runs the Navigator's coroutine to its end,
spinning the context meanwhile as rclpy's ``spin_until_future_complete`` does, so the program's
other callbacks run as they would under rclpy. A method that starts a task (``goToPose``,
``followWaypoints``, ``followPath``, ``spin``, ...) returns its :class:`RunningTask`, or None when the
goal was rejected (``getTaskError()`` says so); ``isTaskComplete`` spins up to 0.1 s for the result,
as upstream. A goal sent while a task runs replaces it (the server preempts the running goal).

A BasicNavigator method whose Navigator coroutine aiorobot lacks raises ``NotProvidedError`` naming it.
"""

from __future__ import annotations

import enum
from typing import Any

from ...nav import Navigator, TaskResult
from .._missing import not_provided
from .._node import make_node_class, raw

__all__ = ["BasicNavigator", "RunningTask", "TaskResult"]


class RunningTask(enum.Enum):
    """nav2_simple_commander's RunningTask (what a task-starting method returns)."""

    NONE = 0
    NAVIGATE_TO_POSE = 1
    NAVIGATE_THROUGH_POSES = 2
    FOLLOW_PATH = 3
    FOLLOW_WAYPOINTS = 4
    FOLLOW_GPS_WAYPOINTS = 5
    SPIN = 6
    BACKUP = 7
    DRIVE_ON_HEADING = 8
    ASSISTED_TELEOP = 9
    DOCK_ROBOT = 10
    UNDOCK_ROBOT = 11
    COMPUTE_AND_TRACK_ROUTE = 12
    FOLLOW_OBJECT = 13


#: BasicNavigator's blocking method -> (the Navigator coroutine it runs, the task it starts or None)
_BLOCKING: dict[str, tuple[str, RunningTask | None]] = {
    "goToPose": ("go_to_pose", RunningTask.NAVIGATE_TO_POSE),
    "goThroughPoses": ("go_through_poses", RunningTask.NAVIGATE_THROUGH_POSES),
    "followWaypoints": ("follow_waypoints", RunningTask.FOLLOW_WAYPOINTS),
    "followPath": ("follow_path", RunningTask.FOLLOW_PATH),
    "spin": ("spin", RunningTask.SPIN),
    "backup": ("backup", RunningTask.BACKUP),
    "driveOnHeading": ("drive_on_heading", RunningTask.DRIVE_ON_HEADING),
    "getPath": ("get_path", None),
    "getPathThroughPoses": ("get_path_through_poses", None),
    "smoothPath": ("smooth_path", None),
    "changeMap": ("change_map", None),
    "clearAllCostmaps": ("clear_all_costmaps", None),
    "clearLocalCostmap": ("clear_local_costmap", None),
    "clearGlobalCostmap": ("clear_global_costmap", None),
    "getGlobalCostmap": ("get_global_costmap", None),
    "getLocalCostmap": ("get_local_costmap", None),
    "waitUntilNav2Active": ("wait_until_nav2_active", None),
    "lifecycleStartup": ("lifecycle_startup", None),
    "lifecycleShutdown": ("lifecycle_shutdown", None),
}

_Base: Any = make_node_class(Navigator, "_BasicNavigatorNode", __name__, "rclpy's Node over aiorobot's Navigator.")


def _blocking(name: str, coroutine: str, task: RunningTask | None) -> Any:
    def method(self: BasicNavigator, *args: Any, **kwargs: Any) -> Any:
        fn = getattr(self, coroutine, None)
        if fn is None:
            raise not_provided(f"nav2_simple_commander BasicNavigator.{name}")
        if task is not None:
            self.clearPreviousState()
        out = self._block(fn(*args, **kwargs), f"BasicNavigator.{name}")
        if task is None:
            return None if coroutine.startswith("lifecycle_") else out  # upstream's return None
        if not out:
            self.setTaskError(0, f"{name}: the goal was rejected or no server answered (see the log)")
            return None
        return task

    method.__name__ = method.__qualname__ = name
    method.__doc__ = f"BasicNavigator's ``{name}``: runs :meth:`aiorobot.nav.Navigator.{coroutine}` to its end."
    return method


class BasicNavigator(_Base):
    """nav2_simple_commander's BasicNavigator (blocking), run by ``aiorobot exec``; see the module docstring."""

    def __init__(self, node_name: str = "basic_navigator", namespace: str = "") -> None:
        self._compat_raw = 1  # the Navigator's own entities are aiorobot's (awaited by its coroutines)
        super().__init__(node_name, namespace=namespace)
        self._compat_raw = 0
        self.last_action_error_code = 0
        self.last_action_error_msg = ""

    def _block(self, coro: Any, what: str) -> Any:
        with raw(self):
            return self.context.run_sync(coro, what)

    def isTaskComplete(self, task: RunningTask | None = RunningTask.NONE) -> bool:  # noqa: N802
        """Spin up to 0.1 s for the running task's result; True once it has ended (or none runs)."""
        if task is None:
            self.error("Task is None, cannot check for completion")
            return False
        if not self.is_task_complete():
            self._block(self._result_within(0.1), "BasicNavigator.isTaskComplete")
        if not self.is_task_complete():
            return False
        if self.get_result() is not TaskResult.SUCCEEDED:
            result = self.result
            if result is not None and hasattr(result, "error_code"):
                self.setTaskError(int(result.error_code), str(getattr(result, "error_msg", "")))
            elif result is None:
                self.setTaskError(0, "No result received")
        return True

    async def _result_within(self, timeout_sec: float) -> None:
        try:
            await self.wait_for_task(timeout_sec=timeout_sec)
        except TimeoutError:
            pass

    def getFeedback(self, task: RunningTask = RunningTask.NONE) -> Any:  # noqa: N802
        return self.get_feedback()

    def getResult(self) -> TaskResult:  # noqa: N802
        return self.get_result()

    def cancelTask(self) -> None:  # noqa: N802
        self.info("Canceling current task.")
        self._block(self.cancel_task(), "BasicNavigator.cancelTask")
        self.clearPreviousState()

    def setInitialPose(self, initial_pose: Any) -> None:  # noqa: N802
        self.set_initial_pose(initial_pose)

    def clearPreviousState(self) -> None:  # noqa: N802
        self.last_action_error_code = 0
        self.last_action_error_msg = ""

    def setTaskError(self, error_code: int, error_msg: str) -> None:  # noqa: N802
        self.last_action_error_code = error_code
        self.last_action_error_msg = error_msg

    def getTaskError(self) -> tuple[int, str]:  # noqa: N802
        return (self.last_action_error_code, self.last_action_error_msg)

    def destroyNode(self) -> None:  # noqa: N802
        self.destroy_node()

    def info(self, msg: str) -> None:
        self.get_logger().info(msg)

    def warn(self, msg: str) -> None:
        self.get_logger().warning(msg)

    def error(self, msg: str) -> None:
        self.get_logger().error(msg)

    def debug(self, msg: str) -> None:
        self.get_logger().debug(msg)


for _name, (_coroutine, _task) in _BLOCKING.items():
    setattr(BasicNavigator, _name, _blocking(_name, _coroutine, _task))
