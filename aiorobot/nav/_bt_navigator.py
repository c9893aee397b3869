"""Nav2's bt_navigator part of the navigation server: one pose of a navigation goal, driven by a tree.

For each pose the server builds the tree (its ``default_nav_to_pose_bt_xml``, or the goal's own
``behavior_tree`` file, or :data:`~._bt_nav2.DEFAULT_TREE`), puts ``goal`` and its own recovery
parameters on the blackboard (``number_of_retries`` = ``max_recoveries``, ``replan_hz`` =
1 / ``replan_period``, ``spin_dist``, ``wait_duration``, ``backup_dist``, ``backup_speed``) and
ticks it every ``bt_loop_duration`` until it succeeds or fails, publishing feedback.

Around the tree, as before it: a cancel halts it and stops the base; localisation lost halts it,
stops the base and aborts unless the estimate comes back within ``localization_recovery_timeout``
(the tree then starts over); a failed tree aborts with the planner's or the controller's error
code and message from the blackboard (Nav2's ``error_code_names``), the planner's first.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from ._bt import Blackboard, Status, TreeError, load_tree
from ._bt_nav2 import DEFAULT_TREE, nav2_registry
from ._geometry import pose_stamped

__all__ = ["navigate_with_tree", "tree_source"]


def tree_source(server: Any, requested: str) -> tuple[str, str]:
    """(XML, where from) for a goal whose ``behavior_tree`` field is ``requested`` ('' = the server's)."""
    path = requested or server.default_bt_xml
    if not path:
        return DEFAULT_TREE, "the default NavigateToPose tree"
    try:
        return Path(path).read_text(encoding="utf8"), path
    except OSError as err:
        raise TreeError(f"{path}: cannot read the behaviour tree ({err.strerror})") from None


def _remaining(path: np.ndarray | None, pose: tuple[float, float, float]) -> float:
    if path is None or not len(path):
        return 0.0
    i = int(np.argmin(np.hypot(path[:, 0] - pose[0], path[:, 1] - pose[1])))
    rest = path[i:, :2]
    return math.hypot(rest[0, 0] - pose[0], rest[0, 1] - pose[1]) + float(np.hypot(*np.diff(rest, axis=0).T).sum())


async def navigate_with_tree(server: Any, handle: Any, target: Any, action: Any, nav_start: Any, *, remaining: int,
                             feedback: bool = True) -> bool:
    """Drive to ``target`` (a PoseStamped) with the tree; True on arrival, False when canceled.

    Raises the server's ``_Abort`` with Nav2's error code and the reason on failure.
    """
    from aiorobot import Duration

    from ._navigation_server import NavigationFailure, _Abort, _Preempted

    s = server
    await s._wait_for_map()
    await s._wait_for_robot_pose()
    if s.localization_lost is not None:
        raise _Abort(NavigationFailure.UNKNOWN, f"localisation lost: {s.localization_lost}; not driving")
    requested = str(getattr(handle.request, "behavior_tree", "") or "")
    try:
        xml, where = tree_source(s, requested)
        clock = s.get_clock()
        board = Blackboard(goal=target, number_of_retries=s.max_recoveries, replan_hz=1.0 / s.replan_period,
                           spin_dist=s.spin_dist, wait_duration=s.wait_duration, backup_dist=s.backup_dist,
                           backup_speed=s.backup_speed)
        tree = load_tree(xml, nav2_registry(s), now=lambda: clock.now().nanoseconds / 1e9, blackboard=board, source=where)
    except TreeError as err:
        raise _Abort(NavigationFailure.FAILED_TO_LOAD_BEHAVIOR_TREE, str(err)) from None
    period = s.bt_loop_duration
    start = clock.now()
    lost_since: float | None = None
    try:
        while True:
            t = (clock.now() - start).nanoseconds / 1e9  # a sleep may last longer than asked (sim time steps)
            if handle.is_cancel_requested:
                return False
            if s._preempt:
                raise _Preempted()
            if s.localization_lost is not None:
                tree.halt()
                s._stop_base()
                if lost_since is None:
                    lost_since = t
                    s.get_logger().warning(f"localisation lost ({s.localization_lost}): stopped; waiting up to "
                                           f"{s.localization_recovery_timeout:g} s for it to come back")
                if t - lost_since >= s.localization_recovery_timeout:
                    raise _Abort(NavigationFailure.UNKNOWN, f"localisation lost: {s.localization_lost} for "
                                                            f"{s.localization_recovery_timeout:g} s")
            else:
                if lost_since is not None:
                    s.get_logger().info("localisation back: driving on")
                    lost_since = None
                status = tree.tick()
                if status is Status.SUCCESS:
                    return True
                if status is Status.FAILURE:
                    raise _failure(board, s.recoveries)
            if feedback:
                _publish_feedback(s, handle, action, nav_start, board.get("path"), remaining, Duration)
            await clock.sleep_for(period)
    finally:
        tree.halt()
        s._stop_base()


def _failure(board: Blackboard, recoveries: int) -> Exception:
    from ._navigation_server import NavigationFailure, _Abort

    for kind in ("compute_path", "follow_path"):
        code = int(board.get(f"{kind}_error_code", 0) or 0)
        if code:
            message = str(board.get(f"{kind}_error_msg", "")) or f"{kind} failed"
            if recoveries:
                message += f" ({recoveries} recoveries did not help)"
            return _Abort(NavigationFailure.UNKNOWN, message, code=code)
    return _Abort(NavigationFailure.UNKNOWN, f"the behaviour tree failed after {recoveries} recoveries")


def _publish_feedback(s: Any, handle: Any, action: Any, nav_start: Any, path: Any, remaining: int, duration: Any) -> None:
    pose = s._robot_pose()
    fb = action.Feedback()
    fb.current_pose = pose_stamped(*pose, s.global_frame, s.now().to_msg())
    fb.navigation_time = (s.now() - nav_start).to_msg()
    dist = _remaining(path if isinstance(path, np.ndarray) else None, pose)
    fb.distance_remaining = float(dist)
    speed = s.last_speed
    fb.estimated_time_remaining = duration(seconds=dist / abs(speed) if abs(speed) > 1e-3 else 0.0).to_msg()
    fb.number_of_recoveries = s.recoveries
    if hasattr(fb, "number_of_poses_remaining"):
        fb.number_of_poses_remaining = remaining
    handle.publish_feedback(fb)
