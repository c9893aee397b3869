"""Nav2's behaviour, controller, planner, smoother and costmap interfaces on the navigation server.

One navigation server plays the parts Nav2 splits over several servers, under their names:

- behavior_server: actions ``spin`` (nav2_msgs/Spin: turn by ``target_yaw``), ``backup``
  (BackUp: drive ``target.x`` backwards at ``speed``) and ``drive_on_heading`` (DriveOnHeading:
  straight ahead or back, ``target.x`` and ``speed`` of one sign), each within ``time_allowance``
  (TIMEOUT otherwise); a straight drive stops with COLLISION_AHEAD when the pose
  ``simulate_ahead_time`` ahead on its line is lethal or inscribed (Nav2's collision check; a round
  robot turning in place cannot hit anything, so spin has none);
- controller_server: ``follow_path`` (FollowPath: the server's controller along a given path, with
  the progress checker's ``required_movement_radius`` / ``movement_time_allowance``);
- planner_server: ``compute_path_through_poses`` (A* leg by leg, joined);
- smoother_server: ``smooth_path`` (SmoothPath: nav2_smoother's SimpleSmoother, optionally
  refused when the result touches an obstacle);
- the costmaps' services ``global_costmap/clear_entirely_global_costmap``,
  ``local_costmap/clear_entirely_local_costmap``, ``global_costmap/get_costmap`` and
  ``local_costmap/get_costmap``. The server keeps one costmap, which plays both parts: clearing
  either clears its obstacle layer, and both return it.

A behaviour, like a navigation goal, takes the base: one is refused while another runs.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ._costmap import INSCRIBED_INFLATED_OBSTACLE, NO_INFORMATION
from ._geometry import wrap_angle, xyyaw

__all__ = ["Behaviors", "smooth_path"]


def smooth_path(xy: NDArray[np.float64], *, w_data: float = 0.2, w_smooth: float = 0.3, tolerance: float = 1e-10,
                max_its: int = 1000) -> NDArray[np.float64]:
    """nav2_smoother's SimpleSmoother on (N, 2) points: gradient steps pulling each inner point toward
    its original (``w_data``) and its neighbours' midpoint (``w_smooth``) until the change per pass is
    below ``tolerance`` or ``max_its`` passes; the end points stay."""
    orig = np.asarray(xy, dtype=np.float64)
    out = orig.copy()
    if len(out) < 3:
        return out
    for _ in range(max_its):
        before = out.copy()
        for i in range(1, len(out) - 1):
            out[i] += w_data * (orig[i] - out[i]) + w_smooth * (out[i - 1] + out[i + 1] - 2.0 * out[i])
        if float(np.sum((out - before) ** 2)) < tolerance:
            break
    return out


def _seconds(duration_msg: Any) -> float:
    from aiorobot import Duration

    return Duration.from_msg(duration_msg).nanoseconds / 1e9


def _yaws(xy: NDArray[np.float64], last_yaw: float) -> NDArray[np.float64]:
    d = np.diff(xy, axis=0)
    return np.append(np.arctan2(d[:, 1], d[:, 0]), last_yaw) if len(xy) > 1 else np.array([last_yaw])


class Behaviors:
    """Installs the interfaces above on ``server`` (a NavigationServer); see the module doc."""

    def __init__(self, server: Any) -> None:
        from aiorobot.msgs.nav2_msgs import (BackUp, ClearEntireCostmap, ComputePathThroughPoses, DriveOnHeading,
                                             FollowPath, GetCostmap, SmoothPath, Spin)

        from ._navigation_server import _accept_cancel

        self.s = server
        d = server.declare_parameter
        self.simulate_ahead_time = float(d("simulate_ahead_time", 2.0).value)
        self.max_rotational_vel = float(d("max_rotational_vel", 1.0).value)
        self.min_rotational_vel = float(d("min_rotational_vel", 0.4).value)
        self.rotational_acc_lim = float(d("rotational_acc_lim", 3.2).value)
        accept = server._accept
        for action, name, run in ((Spin, "spin", self._spin), (BackUp, "backup", self._backup),
                                  (DriveOnHeading, "drive_on_heading", self._drive_on_heading),
                                  (FollowPath, "follow_path", self._follow_path)):
            server.create_action_server(action, name, self._exclusive(run), goal_callback=accept, cancel_callback=_accept_cancel)
        server.create_action_server(ComputePathThroughPoses, "compute_path_through_poses", self._through_poses,
                                    cancel_callback=_accept_cancel)
        server.create_action_server(SmoothPath, "smooth_path", self._smooth, cancel_callback=_accept_cancel)
        for which in ("global", "local"):
            server.create_service(ClearEntireCostmap, f"{which}_costmap/clear_entirely_{which}_costmap", self._clear)
            server.create_service(GetCostmap, f"{which}_costmap/get_costmap", self._get_costmap)

    def _exclusive(self, run: Any) -> Any:
        async def wrapped(handle: Any) -> Any:
            self.s._busy = True
            try:
                return await run(handle)
            finally:
                self.s._stop_base()
                self.s._busy = False

        return wrapped

    # -- behavior_server ---------------------------------------------------------------

    async def _spin(self, handle: Any) -> Any:
        from aiorobot.msgs.nav2_msgs import Spin

        goal = handle.request
        return await self._act(handle, Spin, self.spin(float(goal.target_yaw), _seconds(goal.time_allowance),
                                                        feedback=lambda v: handle.publish_feedback(
                                                            Spin.Feedback(angular_distance_traveled=v)),
                                                        cancelled=lambda: handle.is_cancel_requested))

    async def _backup(self, handle: Any) -> Any:
        from aiorobot.msgs.nav2_msgs import BackUp

        goal = handle.request
        # BackUp::onRun: always backwards, whatever the signs given
        return await self._act(handle, BackUp, self.drive(-abs(float(goal.target.x)), -abs(float(goal.speed)),
                                                          _seconds(goal.time_allowance),
                                                          feedback=lambda v: handle.publish_feedback(
                                                              BackUp.Feedback(distance_traveled=v)),
                                                          cancelled=lambda: handle.is_cancel_requested))

    async def _drive_on_heading(self, handle: Any) -> Any:
        from aiorobot.msgs.nav2_msgs import DriveOnHeading

        goal = handle.request
        dist, speed = float(goal.target.x), float(goal.speed)
        if dist * speed <= 0.0 or goal.target.y != 0.0 or goal.target.z != 0.0:
            return self._fail(handle, DriveOnHeading.Result(), DriveOnHeading.Result.INVALID_INPUT,
                              f"drive_on_heading: expected target.x and speed of one sign, non-zero, and target.y = "
                              f"target.z = 0, found target ({goal.target.x:g}, {goal.target.y:g}, {goal.target.z:g}) "
                              f"and speed {speed:g}")
        return await self._act(handle, DriveOnHeading, self.drive(dist, speed, _seconds(goal.time_allowance),
                                                                  feedback=lambda v: handle.publish_feedback(
                                                                      DriveOnHeading.Feedback(distance_traveled=v)),
                                                                  cancelled=lambda: handle.is_cancel_requested))

    async def _act(self, handle: Any, action: Any, run: Any) -> Any:
        """Await a behaviour's core and end its goal: succeeded, canceled, or aborted with Nav2's code."""
        from aiorobot import Duration

        result = action.Result()
        t0 = self.s.now()
        outcome, message = await run
        if hasattr(result, "total_elapsed_time"):
            result.total_elapsed_time = Duration(nanoseconds=(self.s.now() - t0).nanoseconds).to_msg()
        if outcome == "SUCCEEDED":
            handle.succeed()
        elif outcome == "CANCELED":
            handle.canceled()
        else:
            self._fail(handle, result, getattr(action.Result, outcome), message)
        return result

    # -- the behaviours' cores (the action servers above and the behaviour tree's leaves run these) --

    async def spin(self, target_yaw: float, allowance: float, *, feedback: Callable[[float], None] | None = None,
                   cancelled: Callable[[], bool] = lambda: False) -> tuple[str, str]:
        """Turn by ``target_yaw`` (rad, + counter-clockwise) within ``allowance`` s (0: no limit).

        Returns (``SUCCEEDED`` | ``CANCELED`` | a Spin result code name, a reason); the base stops at the end.
        """
        s = self.s
        try:
            try:
                _, _, yaw0 = s._robot_pose()
            except Exception as err:  # the server's TF_ERROR abort
                return "TF_ERROR", str(err)
            clock, period = s.get_clock(), 1.0 / s.frequency
            start = clock.now()
            turned, prev, speed, t = 0.0, yaw0, 0.0, 0.0
            target = abs(float(target_yaw))
            sign = math.copysign(1.0, float(target_yaw))
            while turned < target - 1e-3:
                if cancelled():
                    return "CANCELED", "canceled"
                if allowance > 0 and t >= allowance:
                    return "TIMEOUT", f"spin: {turned:.2f} of {target:.2f} rad in the time allowance {allowance:g} s"
                # Spin::onCycleUpdate: v = sqrt(2 a remaining), within [min, max]_rotational_vel
                remaining = target - turned
                speed = min(max(math.sqrt(2.0 * self.rotational_acc_lim * remaining), self.min_rotational_vel),
                            self.max_rotational_vel, speed + self.rotational_acc_lim * period)
                s._send(0.0, sign * speed)
                if feedback is not None:
                    feedback(float(turned))
                await clock.sleep_for(period)
                t = (clock.now() - start).nanoseconds / 1e9  # a sleep may outlast its period on sim time
                yaw = s._robot_pose()[2]
                turned += abs(wrap_angle(yaw - prev))
                prev = yaw
            return "SUCCEEDED", ""
        finally:
            s._stop_base()

    async def drive(self, dist: float, speed: float, allowance: float, *, feedback: Callable[[float], None] | None = None,
                    cancelled: Callable[[], bool] = lambda: False) -> tuple[str, str]:
        """DriveOnHeading's cycle: drive at ``speed`` (m/s; negative: backwards) until |``dist``| is covered,
        checking the line ahead. Returns as :meth:`spin` (codes of DriveOnHeading / BackUp)."""
        s = self.s
        try:
            try:
                x0, y0, _ = s._robot_pose()
            except Exception as err:
                return "TF_ERROR", str(err)
            clock, period = s.get_clock(), 1.0 / s.frequency
            start = clock.now()
            t, travelled = 0.0, 0.0
            while travelled < abs(dist):
                if cancelled():
                    return "CANCELED", "canceled"
                if allowance > 0 and t >= allowance:
                    return "TIMEOUT", f"{travelled:.2f} of {abs(dist):.2f} m in the time allowance {allowance:g} s"
                x, y, yaw = s._robot_pose()
                if self._blocked_ahead(x, y, yaw, speed, abs(dist) - travelled):
                    return "COLLISION_AHEAD", f"collision ahead within {self.simulate_ahead_time:g} s at {abs(speed):g} m/s"
                s._send(speed, 0.0)
                if feedback is not None:
                    feedback(float(travelled))
                await clock.sleep_for(period)
                t = (clock.now() - start).nanoseconds / 1e9  # a sleep may outlast its period on sim time
                x, y, _ = s._robot_pose()
                travelled = math.hypot(x - x0, y - y0)
            return "SUCCEEDED", ""
        finally:
            s._stop_base()

    def _blocked_ahead(self, x: float, y: float, yaw: float, speed: float, remaining: float) -> bool:
        """DriveOnHeading::isCollisionFree: poses along the line, up to simulate_ahead_time (and no
        further than the distance left), on a lethal or inscribed cell."""
        cm = self.s.costmap
        if cm is None:
            return False
        reach = min(abs(speed) * self.simulate_ahead_time, remaining)
        step = cm.resolution
        sign = math.copysign(1.0, speed)
        for i in range(1, int(reach / step) + 2):
            d = min(i * step, reach)
            c = cm.cost_at(x + sign * d * math.cos(yaw), y + sign * d * math.sin(yaw))
            if INSCRIBED_INFLATED_OBSTACLE <= c < NO_INFORMATION:
                return True
        return False

    @staticmethod
    def _fail(handle: Any, result: Any, code: int, message: str) -> Any:
        handle.abort()
        result.error_code, result.error_msg = int(code), message
        return result

    # -- controller_server -------------------------------------------------------------

    async def _follow_path(self, handle: Any) -> Any:
        from aiorobot.msgs.nav2_msgs import FollowPath

        s, result = self.s, FollowPath.Result()
        poses = np.array([xyyaw(p) for p in handle.request.path.poses], dtype=np.float64).reshape(-1, 3)
        if not len(poses):
            return self._fail(handle, result, FollowPath.Result.INVALID_PATH, "follow_path: the path has no poses")
        try:
            await s._wait_for_map()
            await s._wait_for_robot_pose()
        except Exception as err:
            return self._fail(handle, result, FollowPath.Result.TF_ERROR, str(err))
        return await self._act(handle, FollowPath, self.follow(lambda: poses, feedback=lambda d, v: handle.publish_feedback(
            FollowPath.Feedback(distance_to_goal=d, speed=v)), cancelled=lambda: handle.is_cancel_requested))

    async def follow(self, path: Callable[[], NDArray[np.float64]], *, feedback: Callable[[float, float], None] | None = None,
                     cancelled: Callable[[], bool] = lambda: False) -> tuple[str, str]:
        """controller_server's loop: the selected controller along ``path()`` (N, 3), taken up again
        whenever it returns a new array, until the goal checker is satisfied. The progress checker
        (``required_movement_radius`` in ``movement_time_allowance``) and a second of no
        collision-free command fail it. Returns as :meth:`spin` (codes of FollowPath)."""
        s = self.s
        controller = s._new_controller()
        current = path()
        controller.set_plan(current)
        clock, period = s.get_clock(), 1.0 / s.frequency
        start = clock.now()
        t, speed = 0.0, 0.0
        ref_pose, ref_t = s._robot_pose(), 0.0
        blocked_since: float | None = None
        try:
            while True:
                if cancelled():
                    return "CANCELED", "canceled"
                if path() is not current:  # a new plan: the same controller takes it up (Nav2's setPlan)
                    current = path()
                    controller.set_plan(current)
                pose = s._robot_pose()
                s.filters.update(controller, pose[0], pose[1])  # the speed filter's limit where the robot is
                cmd = controller.step(pose, speed)
                if cmd.goal_reached:
                    return "SUCCEEDED", ""
                if cmd.collision_ahead:
                    blocked_since = t if blocked_since is None else blocked_since
                    if t - blocked_since >= 1.0:
                        return "NO_VALID_CONTROL", "no collision-free command for 1 s"
                else:
                    blocked_since = None
                # SimpleProgressChecker
                if math.hypot(pose[0] - ref_pose[0], pose[1] - ref_pose[1]) >= s.required_movement_radius or cmd.rotating:
                    ref_pose, ref_t = pose, t
                elif t - ref_t >= s.movement_time_allowance:
                    return "FAILED_TO_MAKE_PROGRESS", (f"moved less than {s.required_movement_radius:g} m in "
                                                       f"{s.movement_time_allowance:g} s")
                lateral = getattr(cmd, "lateral", 0.0)
                s._send(cmd.linear, cmd.angular, lateral)
                speed = cmd.linear
                if feedback is not None:
                    feedback(float(controller.remaining(pose[0], pose[1])), float(math.hypot(cmd.linear, lateral)))
                await clock.sleep_for(period)
                t = (clock.now() - start).nanoseconds / 1e9  # a sleep may outlast its period on sim time
        finally:
            s._stop_base()

    # -- planner_server and smoother_server ------------------------------------------------

    async def _through_poses(self, handle: Any) -> Any:
        from aiorobot import Duration
        from aiorobot.msgs.nav2_msgs import ComputePathThroughPoses

        from ._navigation_server import _Abort
        from ._planner import Plan

        s, req, result = self.s, handle.request, ComputePathThroughPoses.Result()
        t0 = time.perf_counter()
        if not req.goals:
            return self._fail(handle, result, ComputePathThroughPoses.Result.NO_VIAPOINTS_GIVEN,
                              "compute_path_through_poses: no goals given")
        try:
            await s._wait_for_map()
            if not req.use_start:
                await s._wait_for_robot_pose()  # a planner asked at start-up waits for tf, up to transform_timeout
            start = xyyaw(req.start) if req.use_start else s._robot_pose()
            legs = []
            for goal in req.goals:
                leg = s._plan(start, xyyaw(goal))
                legs.append(leg.poses if not legs else leg.poses[1:])
                start = tuple(leg.poses[-1])
            poses = np.concatenate(legs)
            joined = Plan(poses, float(np.hypot(*np.diff(poses[:, :2], axis=0).T).sum()), 0.0)
            result.path = s._path_msg(joined)
            handle.succeed()
        except _Abort as err:
            code = getattr(ComputePathThroughPoses.Result, err.kind.name, ComputePathThroughPoses.Result.UNKNOWN)
            self._fail(handle, result, code, str(err))
        result.planning_time = Duration(seconds=time.perf_counter() - t0).to_msg()
        return result

    async def _smooth(self, handle: Any) -> Any:
        from aiorobot import Duration
        from aiorobot.msgs.nav2_msgs import SmoothPath
        from aiorobot.msgs.nav_msgs import Path

        from ._geometry import pose_stamped

        s, req, result = self.s, handle.request, SmoothPath.Result()
        t0 = time.perf_counter()
        poses = [xyyaw(p) for p in req.path.poses]
        if not poses:
            return self._fail(handle, result, SmoothPath.Result.INVALID_PATH, "smooth_path: the path has no poses")
        xy = smooth_path(np.array([p[:2] for p in poses]))
        if req.check_for_collisions and s.costmap is not None:
            costs = [s.costmap.cost_at(x, y) for x, y in xy]
            if any(INSCRIBED_INFLATED_OBSTACLE <= c < NO_INFORMATION for c in costs):
                return self._fail(handle, result, SmoothPath.Result.SMOOTHED_PATH_IN_COLLISION,
                                  "smooth_path: the smoothed path runs within the robot's radius of an obstacle")
        frame = req.path.header.frame_id or s.global_frame
        msg = Path()
        msg.header = req.path.header
        msg.header.frame_id = frame
        msg.poses = [pose_stamped(x, y, yaw, frame, req.path.header.stamp) for (x, y), yaw in zip(xy, _yaws(xy, poses[-1][2]))]
        result.path = msg
        result.was_completed = True
        result.smoothing_duration = Duration(seconds=time.perf_counter() - t0).to_msg()
        handle.succeed()
        return result

    # -- costmap services ------------------------------------------------------------------

    def _clear(self, request: Any, response: Any) -> Any:
        cm = self.s.costmap
        if cm is not None:
            cm.clear_obstacles()
            cm.update()
        return response

    def _get_costmap(self, request: Any, response: Any) -> Any:
        from aiorobot.msgs.geometry_msgs import Point, Pose
        from aiorobot.msgs.nav2_msgs import Costmap as CostmapMsg

        s, cm = self.s, self.s.costmap
        msg = CostmapMsg()
        msg.header.frame_id = s.global_frame
        msg.header.stamp = s.now().to_msg()
        if cm is None:
            s.get_logger().warning("get_costmap: no /map received yet; returning an empty costmap")
            response.map = msg
            return response
        meta = msg.metadata
        meta.layer = "master"
        meta.resolution = float(cm.resolution)
        meta.size_y, meta.size_x = (int(v) for v in cm.shape)
        meta.origin = Pose(position=Point(x=float(cm.origin[0]), y=float(cm.origin[1])))
        meta.update_time = msg.header.stamp
        msg.data = cm.cost.reshape(-1).copy()
        response.map = msg
        return response
