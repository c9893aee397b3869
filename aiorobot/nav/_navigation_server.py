"""``NavigationServer``: Nav2's navigate_to_pose, navigate_through_poses, follow_waypoints and
compute_path_to_pose actions over the pure cores (costmap, planner, Regulated Pure Pursuit).

It keeps a global costmap (static layer from ``/map`` + obstacle layer from ``/scan`` +
inflation), reads the robot pose from tf (``global_frame`` -> ``robot_base_frame``), plans with A*,
replans every ``replan_period`` (Nav2's default behaviour tree replans at 1 Hz), follows the path
with RPP at ``controller_frequency`` and publishes ``/cmd_vel`` and ``/plan``.

When blocked (collision ahead, no progress within ``movement_time_allowance``, no path) it runs
Nav2's recoveries in turn, counting ``number_of_recoveries``: clear the obstacle layer and replan,
wait, back up, spin; past ``max_recoveries`` the goal is aborted with the reason. A goal outside the
map or in an obstacle is aborted at once with Nav2's error code and message; a cancel stops the
base and ends CANCELED; no ``/map`` within ``map_timeout`` aborts.

A ``geometry_msgs/PoseStamped`` on ``goal_pose`` (the topic RViz's and Foxglove's "2D Goal Pose"
publish) is sent as a ``navigate_to_pose`` goal to this node's own action server, as Nav2's
bt_navigator does; a goal refused (another navigation action is running) is logged.

A new navigate_to_pose (navigate_through_poses, follow_waypoints) goal replaces the running one
of its action, which ends ABORTED, as Nav2's; a goal for another navigation action while one runs
is refused (see :mod:`._preemption`).

Localisation lost: the pose estimate on ``localization_topic`` (AMCL's ``amcl_pose``, a
PoseWithCovarianceStamped; ``localization_type = "odometry"`` for an EKF's nav_msgs/Odometry) with a position standard deviation above
``max_localization_std`` (m) or a heading one above ``max_localization_yaw_std`` (rad) stops the
base at once; the goal aborts with the reason unless the estimate comes back within
``localization_recovery_timeout`` (s). A goal that arrives while lost aborts before driving. No
message on the topic (a graph without that estimator) means no check.
"""

from __future__ import annotations

import enum
import math
import time
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from .._core._node import Node
from .._core._warm_up import compile_kernels
from .._core._qos import QoSProfile, ReliabilityPolicy
from ._costmap import Costmap
from ._geometry import pose_stamped, transform_to_xyyaw, xyyaw
from ._map_server import MAP_QOS
from ._maps import OccupancyMap
from ._planner import Plan, PlanError, PlanFailure, plan
from ._preemption import GoalPreemption
from ._rpp import RegulatedPurePursuit, RppParameters

__all__ = ["NavigationFailure", "NavigationServer", "NavigationStatistics"]


class NavigationFailure(enum.Enum):
    """Why a goal aborted, besides the planner's :class:`~aiorobot.nav.PlanFailure`.

    Each name is a code of nav2_msgs ``NavigateToPose.Result`` (``UNKNOWN``, ``TF_ERROR``); the
    value is the code. The Jazzy interface shipped in :mod:`aiorobot.msgs` names only ``NONE``;
    Nav2's newer NavigateToPose.action names UNKNOWN=9000, FAILED_TO_LOAD_BEHAVIOR_TREE=9001 and
    TF_ERROR=9002, the numbers its bt_navigator returns, so those are the values, and :attr:`code`
    takes the interface's constant wherever it defines one.
    """

    UNKNOWN = 9000
    TF_ERROR = 9002

    @property
    def code(self) -> int:
        from aiorobot.msgs.nav2_msgs import NavigateToPose

        return int(getattr(NavigateToPose.Result, self.name, self.value))


def _plan_code(kind: PlanFailure) -> int:
    """The nav2_msgs ComputePathToPose.Result error code for a planner failure (Nav2's planner server's)."""
    from aiorobot.msgs.nav2_msgs import ComputePathToPose

    return int(getattr(ComputePathToPose.Result, kind.name))


#: planner failures no recovery helps with: the goal or the start is off the map, or the goal is occupied
_HOPELESS = (PlanFailure.START_OUTSIDE_MAP, PlanFailure.GOAL_OUTSIDE_MAP, PlanFailure.GOAL_OCCUPIED)


@dataclass(frozen=True, slots=True)
class NavigationStatistics:
    """What :meth:`NavigationServer.statistics` reports (a snapshot)."""

    #: recoveries run for the current goal (or the last one), as the feedback's number_of_recoveries
    recoveries: int
    #: a navigation goal is being executed
    navigating: bool
    #: why the latest pose estimate counts as lost; None when fine or none seen
    localization_lost: str | None


def _accept_cancel(_handle: Any) -> Any:
    from aiorobot import CancelResponse

    return CancelResponse.ACCEPT


class _Abort(Exception):
    """A goal ends aborted: ``kind`` says why, ``code`` is its nav2_msgs result code."""

    def __init__(self, kind: NavigationFailure | PlanFailure, message: str) -> None:
        super().__init__(message)
        self.kind = kind
        self.code = _plan_code(kind) if isinstance(kind, PlanFailure) else kind.code


class NavigationServer(Node):
    """Nav2's navigation actions in one node (parameters keep Nav2's names; see the module doc)."""

    def __init__(self, node_name: str = "navigation_server", **kwargs: Any) -> None:
        super().__init__(node_name, **kwargs)
        d = self.declare_parameter
        self.global_frame = str(d("global_frame", "map").value)
        self.base_frame = str(d("robot_base_frame", "base_link").value)
        self.frequency = float(d("controller_frequency", 20.0).value)
        self.replan_period = float(d("replan_period", 1.0).value)
        self.map_timeout = float(d("map_timeout", 10.0).value)
        self.transform_timeout = float(d("transform_timeout", 10.0).value)
        self.max_recoveries = int(d("max_recoveries", 6).value)
        self.required_movement_radius = float(d("required_movement_radius", 0.5).value)
        self.movement_time_allowance = float(d("movement_time_allowance", 10.0).value)
        self.backup_dist = float(d("backup_dist", 0.15).value)
        self.backup_speed = float(d("backup_speed", 0.05).value)
        self.spin_dist = float(d("spin_dist", 1.57).value)
        self.wait_duration = float(d("wait_duration", 1.0).value)
        self.allow_unknown = bool(d("allow_unknown", True).value)
        self.stop_on_failure = bool(d("stop_on_failure", True).value)
        self.localization_topic = str(d("localization_topic", "amcl_pose").value)
        self.localization_type = str(d("localization_type", "pose").value)
        self.max_localization_std = float(d("max_localization_std", 0.5).value)
        self.max_localization_yaw_std = float(d("max_localization_yaw_std", 0.8).value)
        self.localization_recovery_timeout = float(d("localization_recovery_timeout", 5.0).value)
        self.costmap_params = {
            "robot_radius": float(d("robot_radius", 0.22).value),
            "inflation_radius": float(d("inflation_radius", 0.55).value),
            "cost_scaling_factor": float(d("cost_scaling_factor", 3.0).value),
        }
        defaults = asdict(RppParameters())
        defaults.pop("extra")
        self.rpp_params = RppParameters(**{k: type(v)(d(k, v).value) for k, v in defaults.items() if k != "control_period"},
                                        control_period=1.0 / self.frequency)
        from aiorobot.msgs.geometry_msgs import Twist
        from aiorobot.msgs.nav2_msgs import ComputePathToPose, FollowWaypoints, NavigateThroughPoses, NavigateToPose
        from aiorobot.msgs.nav_msgs import OccupancyGrid, Path
        from aiorobot.msgs.sensor_msgs import LaserScan
        from aiorobot.tf import Buffer, TransformListener

        self.buffer = Buffer()
        self.listener = TransformListener(self.buffer, self)
        self.costmap: Costmap | None = None
        self.map: OccupancyMap | None = None
        self.create_subscription(OccupancyGrid, "/map", self._on_map, MAP_QOS)
        self.create_subscription(LaserScan, "/scan", self._on_scan, QoSProfile(reliability=ReliabilityPolicy.BEST_EFFORT, depth=5))
        self.cmd_pub = self.create_publisher(Twist, "/cmd_vel", 10)
        self.plan_pub = self.create_publisher(Path, "/plan", 1)
        #: why the last pose estimate counts as lost (None: fine, or no estimate seen)
        self.localization_lost: str | None = None
        self._subscribe_localization()
        self._busy = False
        from ._kernels import warm_up

        compile_kernels(self.get_logger(), lambda: warm_up("astar", "shortcut", "raytrace_clear"))  # not at the first goal
        self.create_action_server(NavigateToPose, "navigate_to_pose", self._navigate_to_pose, goal_callback=self._accept, cancel_callback=_accept_cancel)
        self.create_action_server(NavigateThroughPoses, "navigate_through_poses", self._navigate_through_poses, goal_callback=self._accept, cancel_callback=_accept_cancel)
        self.create_action_server(FollowWaypoints, "follow_waypoints", self._follow_waypoints, goal_callback=self._accept, cancel_callback=_accept_cancel)
        self.create_action_server(ComputePathToPose, "compute_path_to_pose", self._compute_path, cancel_callback=_accept_cancel)
        self._self_client = self.create_action_client(NavigateToPose, "navigate_to_pose")
        from aiorobot.msgs.geometry_msgs import PoseStamped

        self.create_subscription(PoseStamped, "goal_pose", self._on_goal_pose, 10)
        self.last_plan: Plan | None = None
        self.recoveries = 0
        self._preemption = GoalPreemption(self, (NavigateToPose.Goal, NavigateThroughPoses.Goal, FollowWaypoints.Goal))

    def statistics(self) -> NavigationStatistics:
        """Recoveries of the current or last goal, whether one is running, the localisation state."""
        return NavigationStatistics(self.recoveries, self._busy, self.localization_lost)

    # -- inputs -------------------------------------------------------------------------

    def _on_map(self, msg: Any) -> None:
        self.map = OccupancyMap.from_msg(msg)
        self.costmap = Costmap.from_occupancy(self.map.data, self.map.width, self.map.height, self.map.resolution,
                                              self.map.origin[:2], **self.costmap_params)

    def _subscribe_localization(self) -> None:
        from aiorobot.msgs.geometry_msgs import PoseWithCovarianceStamped
        from aiorobot.msgs.nav_msgs import Odometry

        kinds = {"pose": PoseWithCovarianceStamped, "odometry": Odometry}
        if self.localization_type not in kinds:
            raise ValueError(f"parameter localization_type: expected 'pose' (PoseWithCovarianceStamped) or "
                             f"'odometry' (nav_msgs/Odometry), found {self.localization_type!r}")
        if self.localization_topic:
            self.create_subscription(kinds[self.localization_type], self.localization_topic, self._on_localization, 10)

    def _on_localization(self, msg: Any) -> None:
        cov = np.asarray(msg.pose.covariance, dtype=np.float64)
        std_xy = math.sqrt(max(float(cov[0]), float(cov[7]), 0.0))
        std_yaw = math.sqrt(max(float(cov[35]), 0.0))
        if not (math.isfinite(std_xy) and math.isfinite(std_yaw)):
            self.localization_lost = f"the pose covariance on {self.localization_topic} is not finite"
        elif std_xy > self.max_localization_std:
            self.localization_lost = (f"position std {std_xy:.2f} m on {self.localization_topic} exceeds "
                                      f"max_localization_std {self.max_localization_std:g} m")
        elif std_yaw > self.max_localization_yaw_std:
            self.localization_lost = (f"heading std {std_yaw:.2f} rad on {self.localization_topic} exceeds "
                                      f"max_localization_yaw_std {self.max_localization_yaw_std:g} rad")
        else:
            self.localization_lost = None

    def _on_scan(self, scan: Any) -> None:
        from aiorobot import Time
        from aiorobot.tf import TransformException

        cm = self.costmap
        if cm is None:
            return
        try:
            t = self.buffer.lookup_transform(self.global_frame, scan.header.frame_id, Time.from_msg(scan.header.stamp))
        except TransformException:
            try:
                t = self.buffer.lookup_transform(self.global_frame, scan.header.frame_id, Time())
            except TransformException:
                return
        lx, ly, lyaw = transform_to_xyyaw(t)
        ranges = np.asarray(scan.ranges, dtype=np.float64)
        angles = lyaw + float(scan.angle_min) + np.arange(len(ranges)) * float(scan.angle_increment)
        finite = np.isfinite(ranges)
        hit = finite & (ranges < float(scan.range_max)) & (ranges >= float(scan.range_min))
        r = np.where(finite, np.minimum(ranges, float(scan.range_max)), float(scan.range_max))
        pts = np.column_stack([lx + r * np.cos(angles), ly + r * np.sin(angles)])
        cm.clear_obstacles()
        cm.mark_scan((lx, ly), pts, hit)
        cm.update()

    def _accept(self, goal: Any) -> Any:
        from aiorobot import GoalResponse

        # idle, or a goal of the running navigation action that replaces it (see _preemption.py)
        return GoalResponse.ACCEPT if not self._busy or self._preemption.preempts(goal) else GoalResponse.REJECT

    async def _on_goal_pose(self, pose: Any) -> None:
        """bt_navigator's onGoalPoseReceived: the pose becomes a navigate_to_pose goal of our own server."""
        from aiorobot.msgs.nav2_msgs import NavigateToPose

        handle = await self._self_client.send_goal(NavigateToPose.Goal(pose=pose))
        if not handle.accepted:
            self.get_logger().warning("goal_pose: navigate_to_pose refused the goal (another navigation action is running)")

    # -- actions ------------------------------------------------------------------------

    async def _navigate_to_pose(self, handle: Any) -> Any:
        from aiorobot.msgs.nav2_msgs import NavigateToPose

        return await self._run_navigation(handle, [handle.request.pose], NavigateToPose)

    async def _navigate_through_poses(self, handle: Any) -> Any:
        from aiorobot.msgs.nav2_msgs import NavigateThroughPoses

        return await self._run_navigation(handle, list(handle.request.poses), NavigateThroughPoses)

    async def _run_navigation(self, handle: Any, poses: list[Any], action: Any) -> Any:
        result = action.Result()
        if not poses:
            handle.abort()
            result.error_code = NavigationFailure.UNKNOWN.code
            result.error_msg = "no poses to navigate to: the goal's pose list is empty"
            return result
        await self._preemption.begin(handle)
        self._busy = True
        self.recoveries = 0
        start = self.now()
        try:
            for i, target in enumerate(poses):
                ok = await self._drive_to(handle, target, action, start, remaining=len(poses) - i - 1)
                if not ok:
                    handle.canceled()
                    return result
            handle.succeed()
        except _Abort as err:
            handle.abort()
            result.error_code, result.error_msg = err.code, str(err)
            self.get_logger().warning(f"navigation aborted: {err}")
        finally:
            self._stop_base()
            self._busy = False
            self._preemption.end()
        return result

    async def _follow_waypoints(self, handle: Any) -> Any:
        from aiorobot.msgs.nav2_msgs import FollowWaypoints, MissedWaypoint, NavigateToPose

        result = FollowWaypoints.Result()
        poses = list(handle.request.poses)
        if not poses:
            handle.abort()
            return result
        await self._preemption.begin(handle)
        self._busy = True
        self.recoveries = 0
        start = self.now()
        missed = []
        try:
            loops = int(handle.request.number_of_loops) + 1
            for _ in range(loops):
                for i in range(int(handle.request.goal_index), len(poses)):
                    handle.publish_feedback(FollowWaypoints.Feedback(current_waypoint=i))
                    try:
                        if not await self._drive_to(handle, poses[i], NavigateToPose, start, remaining=len(poses) - i - 1, feedback=False):
                            handle.canceled()
                            result.missed_waypoints = missed
                            return result
                    except _Abort as err:
                        missed.append(MissedWaypoint(index=i, goal=poses[i], error_code=err.code))
                        self.get_logger().warning(f"waypoint {i} missed: {err}")
                        if self.stop_on_failure:
                            handle.abort()
                            result.missed_waypoints = missed
                            return result
            result.missed_waypoints = missed
            handle.succeed()
        finally:
            self._stop_base()
            self._busy = False
            self._preemption.end()
        return result

    async def _compute_path(self, handle: Any) -> Any:
        from aiorobot.msgs.nav2_msgs import ComputePathToPose

        req = handle.request
        result = ComputePathToPose.Result()
        t0 = time.perf_counter()
        try:
            await self._wait_for_map()
            start = xyyaw(req.start) if req.use_start else self._robot_pose()
            p = self._plan(start, xyyaw(req.goal))
            result.path = self._path_msg(p)
            handle.succeed()
        except _Abort as err:
            result.error_code, result.error_msg = err.code, str(err)
            handle.abort()
        from aiorobot import Duration

        result.planning_time = Duration(seconds=time.perf_counter() - t0).to_msg()
        return result

    # -- the loop -----------------------------------------------------------------------

    async def _wait_for_map(self) -> None:
        clock = self.get_clock()
        waited = 0.0
        while self.costmap is None:
            if waited >= self.map_timeout:
                raise _Abort(NavigationFailure.UNKNOWN, f"no /map received within {self.map_timeout:g} s; start a map server or the simulator")
            await clock.sleep_for(0.1)
            waited += 0.1

    async def _wait_for_robot_pose(self) -> None:
        """Wait (up to ``transform_timeout`` on the node's clock) for global_frame -> robot_base_frame,
        as Nav2 waits for localisation before it drives."""
        from aiorobot import Time

        clock = self.get_clock()
        waited = 0.0
        while not self.buffer.can_transform(self.global_frame, self.base_frame, Time()):
            if waited >= self.transform_timeout:
                self._robot_pose()  # raises the TF_ERROR abort with tf's reason
            await clock.sleep_for(0.05)
            waited += 0.05

    def _robot_pose(self) -> tuple[float, float, float]:
        from aiorobot import Time
        from aiorobot.tf import TransformException

        try:
            return transform_to_xyyaw(self.buffer.lookup_transform(self.global_frame, self.base_frame, Time()))
        except TransformException as err:
            raise _Abort(NavigationFailure.TF_ERROR, f"no transform {self.global_frame} -> {self.base_frame}: {err}") from None

    def _plan(self, start: tuple[float, float, float], goal: tuple[float, float, float]) -> Plan:
        assert self.costmap is not None
        try:
            p = plan(self.costmap, start[:2], goal[:2], goal_yaw=goal[2], allow_unknown=self.allow_unknown)
        except PlanError as err:
            raise _Abort(err.kind, str(err)) from None
        self.last_plan = p
        self.plan_pub.publish(self._path_msg(p))
        return p

    def _path_msg(self, p: Plan) -> Any:
        from aiorobot.msgs.nav_msgs import Path

        stamp = self.now().to_msg()
        msg = Path()
        msg.header.frame_id = self.global_frame
        msg.header.stamp = stamp
        msg.poses = [pose_stamped(x, y, yaw, self.global_frame, stamp) for x, y, yaw in p.poses]
        return msg

    async def _drive_to(self, handle: Any, target: Any, action: Any, nav_start: Any, *, remaining: int, feedback: bool = True) -> bool:
        """Drive to one pose; True on arrival, False when canceled; raises _Abort with the reason."""
        from aiorobot import Duration

        await self._wait_for_map()
        await self._wait_for_robot_pose()
        if self.localization_lost is not None:
            raise _Abort(NavigationFailure.UNKNOWN, f"localisation lost: {self.localization_lost}; not driving")
        goal = xyyaw(target)
        rpp = RegulatedPurePursuit(self.rpp_params, self.costmap)
        clock = self.get_clock()
        period = 1.0 / self.frequency
        last_plan_at = -math.inf
        blocked_since: float | None = None
        progress_ref = (self._robot_pose(), 0.0)
        speed = 0.0
        t = 0.0  # seconds on the node's clock since this pose began
        first_plan = True
        lost_since: float | None = None
        while True:
            if handle.is_cancel_requested:
                self._stop_base()
                return False
            if self.localization_lost is not None:
                self._stop_base()
                if lost_since is None:
                    lost_since = t
                    self.get_logger().warning(f"localisation lost ({self.localization_lost}): stopped; waiting up to "
                                              f"{self.localization_recovery_timeout:g} s for it to come back")
                if t - lost_since >= self.localization_recovery_timeout:
                    raise _Abort(NavigationFailure.UNKNOWN, f"localisation lost: {self.localization_lost} for "
                                                            f"{self.localization_recovery_timeout:g} s")
                await clock.sleep_for(period)
                t += period
                progress_ref = (progress_ref[0], t)  # standing still for this is not a lack of progress
                continue
            if lost_since is not None:
                self.get_logger().info("localisation back: driving on")
                lost_since, last_plan_at = None, -math.inf
            pose = self._robot_pose()
            if t - last_plan_at >= self.replan_period:
                try:
                    rpp.set_plan(self._plan(pose, goal).poses)
                except _Abort as err:
                    if first_plan and err.kind in _HOPELESS:
                        raise  # outside the map / occupied: no recovery helps
                    await self._recover(handle, f"no path ({err})")
                    progress_ref = (self._robot_pose(), t)
                    continue
                first_plan = False
                last_plan_at = t
            cmd = rpp.step(pose, speed)
            if cmd.goal_reached:
                self._stop_base()
                return True
            if cmd.collision_ahead:
                blocked_since = t if blocked_since is None else blocked_since
                if t - blocked_since >= 1.0:
                    await self._recover(handle, "collision ahead")
                    blocked_since, last_plan_at = None, -math.inf
                    progress_ref = (self._robot_pose(), t)
                    continue
            else:
                blocked_since = None
            ref_pose, ref_t = progress_ref
            if math.hypot(pose[0] - ref_pose[0], pose[1] - ref_pose[1]) >= self.required_movement_radius or cmd.rotating:
                progress_ref = (pose, t)
            elif t - ref_t >= self.movement_time_allowance:
                await self._recover(handle, f"no progress for {self.movement_time_allowance:g} s")
                progress_ref, last_plan_at = (self._robot_pose(), t), -math.inf
                continue
            self._send(cmd.linear, cmd.angular)
            speed = cmd.linear
            if feedback:
                fb = action.Feedback()
                fb.current_pose = pose_stamped(*pose, self.global_frame, self.now().to_msg())
                fb.navigation_time = (self.now() - nav_start).to_msg()
                dist = rpp._remaining(pose[0], pose[1])
                fb.distance_remaining = float(dist)
                fb.estimated_time_remaining = Duration(seconds=dist / max(abs(speed), 1e-3) if speed else 0.0).to_msg()
                fb.number_of_recoveries = self.recoveries
                if hasattr(fb, "number_of_poses_remaining"):
                    fb.number_of_poses_remaining = remaining
                handle.publish_feedback(fb)
            await clock.sleep_for(period)
            t += period

    async def _recover(self, handle: Any, why: str) -> None:
        """Nav2's recoveries in turn: clear + wait, back up, spin; abort when the budget is spent."""
        if self.recoveries >= self.max_recoveries:
            raise _Abort(NavigationFailure.UNKNOWN, f"blocked ({why}) and {self.max_recoveries} recoveries did not help")
        kind = ("clear_and_wait", "backup", "spin")[self.recoveries % 3]
        self.recoveries += 1
        self.get_logger().info(f"recovery {self.recoveries}/{self.max_recoveries}: {kind} ({why})")
        clock = self.get_clock()
        self._stop_base()
        if kind == "clear_and_wait" and self.costmap is not None:
            self.costmap.clear_obstacles()
            self.costmap.update()
            await clock.sleep_for(self.wait_duration)
        elif kind == "backup":
            for _ in range(int(self.backup_dist / self.backup_speed * self.frequency)):
                if handle.is_cancel_requested:
                    break
                self._send(-self.backup_speed, 0.0)
                await clock.sleep_for(1.0 / self.frequency)
        else:
            speed = self.rpp_params.rotate_to_heading_angular_vel
            for _ in range(int(self.spin_dist / speed * self.frequency)):
                if handle.is_cancel_requested:
                    break
                self._send(0.0, speed)
                await clock.sleep_for(1.0 / self.frequency)
        self._stop_base()

    def _send(self, linear: float, angular: float) -> None:
        from aiorobot.msgs.geometry_msgs import Twist, Vector3

        self.cmd_pub.publish(Twist(linear=Vector3(x=float(linear)), angular=Vector3(z=float(angular))))

    def _stop_base(self) -> None:
        self._send(0.0, 0.0)
