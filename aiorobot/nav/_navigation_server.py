"""``NavigationServer``: Nav2's navigate_to_pose, navigate_through_poses, follow_waypoints and
compute_path_to_pose actions over the pure cores (costmap, planner, Regulated Pure Pursuit or MPPI).

It keeps a global costmap (static layer from ``/map`` + obstacle layer from ``/scan`` +
inflation), reads the robot pose from tf (``global_frame`` -> ``robot_base_frame``), plans with A*,
replans every ``replan_period`` (Nav2's default behaviour tree replans at 1 Hz), follows the path
at ``controller_frequency`` with the ``controller`` (``rpp``, the default, or ``mppi``; Nav2's plugin
names are accepted too: see :mod:`._controllers`) and publishes ``/cmd_vel`` and ``/plan``.

The robot's shape is Nav2's costmap parameters ``footprint`` (a polygon ``"[[x, y], ...]"``, padded
by ``footprint_padding``) or ``robot_radius``: the costmap inflates by its inscribed radius, and the
planner and the controller's collision check test the footprint at each pose.

Costmap filters as Nav2's (``filters``, each with its ``plugin`` and ``filter_info_topic``): a
keepout mask makes its cells obstacles for the planner, a speed mask caps the controller's speed
where the robot is (see :mod:`aiorobot.nav._filter_inputs`).

Each pose runs a behaviour tree, as Nav2's bt_navigator does (:mod:`._bt_navigator`): Nav2's
default NavigateToPose tree unless ``default_nav_to_pose_bt_xml`` or the goal's ``behavior_tree``
names another BehaviorTree.CPP XML file. When blocked (no collision-free command for a second, no
progress within ``movement_time_allowance``, no path) the default tree runs Nav2's recoveries in
turn, counting ``number_of_recoveries``: clear the costmap, spin ``spin_dist``, wait
``wait_duration``, back up ``backup_dist`` at ``backup_speed``; past ``max_recoveries`` the goal is
aborted with the reason. A goal outside the map or in an obstacle is aborted at once with Nav2's
error code and message; a cancel stops the base and ends CANCELED; no ``/map`` within
``map_timeout`` aborts; a tree that cannot be loaded aborts with FAILED_TO_LOAD_BEHAVIOR_TREE.

A ``geometry_msgs/PoseStamped`` on ``goal_pose`` (the topic RViz's and Foxglove's "2D Goal Pose"
publish) is sent as a ``navigate_to_pose`` goal to this node's own action server, as Nav2's
bt_navigator does (a running goal is preempted by it; a refused one is logged).

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
from ._filter_inputs import FilterInputs
from ._geometry import pose_stamped, transform_to_xyyaw, xyyaw
from ._map_server import MAP_QOS
from ._maps import OccupancyMap
from ._planner import Plan, PlanError, PlanFailure, plan
from ._controllers import controller_name, declare_mppi_parameters
from ._mppi import Mppi
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
    FAILED_TO_LOAD_BEHAVIOR_TREE = 9001
    TF_ERROR = 9002

    @property
    def code(self) -> int:
        from aiorobot.msgs.nav2_msgs import NavigateToPose

        return int(getattr(NavigateToPose.Result, self.name, self.value))


def _plan_code(kind: PlanFailure) -> int:
    """The nav2_msgs ComputePathToPose.Result error code for a planner failure (Nav2's planner server's)."""
    from aiorobot.msgs.nav2_msgs import ComputePathToPose

    return int(getattr(ComputePathToPose.Result, kind.name))


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

    def __init__(self, kind: NavigationFailure | PlanFailure, message: str, code: int | None = None) -> None:
        super().__init__(message)
        self.kind = kind
        #: ``code`` given: another server's result code (a behaviour tree leaf's error_code_id)
        self.code = code if code is not None else _plan_code(kind) if isinstance(kind, PlanFailure) else kind.code


class _Preempted(_Abort):
    """The running goal gives way to a newer one of the same action (Nav2's SimpleActionServer aborts it)."""

    def __init__(self) -> None:
        super().__init__(NavigationFailure.UNKNOWN, "preempted by a newer goal")


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
        #: bt_navigator's: the tree for a goal that names none ('' = Nav2's default tree), and the tick period (ms)
        self.default_bt_xml = str(d("default_nav_to_pose_bt_xml", "").value)
        self.bt_loop_duration = int(d("bt_loop_duration", 10).value) / 1000.0
        self.last_speed = 0.0
        from ._footprint import Footprint

        robot_radius = float(d("robot_radius", 0.22).value)
        try:  # Nav2's costmap parameters: a footprint polygon wins over robot_radius
            footprint = Footprint.from_parameters(d("footprint", "[]").value, robot_radius, float(d("footprint_padding", 0.01).value))
        except ValueError as err:
            raise ValueError(f"{self.get_name()}: {err}") from None
        self.costmap_params = {
            "footprint": footprint,
            "robot_radius": robot_radius,
            "inflation_radius": float(d("inflation_radius", 0.55).value),
            "cost_scaling_factor": float(d("cost_scaling_factor", 3.0).value),
        }
        defaults = asdict(RppParameters())
        defaults.pop("extra")
        self.rpp_params = RppParameters(**{k: type(v)(d(k, v).value) for k, v in defaults.items() if k != "control_period"},
                                        control_period=1.0 / self.frequency)
        self.controller = controller_name(str(d("controller", "rpp").value))
        self.mppi_params = declare_mppi_parameters(self, 1.0 / self.frequency) if self.controller == "mppi" else None
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
        self.filters = FilterInputs(self)  # Nav2's costmap filters: keepout (planner) and speed (controller)
        self._busy = False
        from ._footprint import warm_up as warm_up_footprint
        from ._kernels import warm_up

        from ._mppi_kernels import warm_up as warm_up_mppi

        def warm() -> None:  # not at the first goal
            warm_up("astar", "shortcut", "raytrace_clear")
            if not footprint.is_circular:
                warm_up_footprint()

        compile_kernels(self.get_logger(), warm, *([warm_up_mppi] if self.controller == "mppi" else []))
        #: the navigation action running ('' none) and whether a newer goal of it is waiting to take over
        self._running, self._preempt, self._latest = "", False, object()
        for action, name, run in ((NavigateToPose, "navigate_to_pose", self._navigate_to_pose),
                                  (NavigateThroughPoses, "navigate_through_poses", self._navigate_through_poses),
                                  (FollowWaypoints, "follow_waypoints", self._follow_waypoints)):
            self.create_action_server(action, name, self._preempting(name, action, run), goal_callback=self._accept_or_preempt(name),
                                      cancel_callback=_accept_cancel)
        self.create_action_server(ComputePathToPose, "compute_path_to_pose", self._compute_path, cancel_callback=_accept_cancel)
        self._self_client = self.create_action_client(NavigateToPose, "navigate_to_pose")
        from aiorobot.msgs.geometry_msgs import PoseStamped

        self.create_subscription(PoseStamped, "goal_pose", self._on_goal_pose, 10)
        self.last_plan: Plan | None = None
        self.recoveries = 0
        from ._behaviors import Behaviors

        #: Nav2's behavior, controller, planner, smoother and costmap interfaces (see _behaviors.py)
        self.behaviors = Behaviors(self)

    def statistics(self) -> NavigationStatistics:
        """Recoveries of the current or last goal, whether one is running, the localisation state."""
        return NavigationStatistics(self.recoveries, self._busy, self.localization_lost)

    # -- inputs -------------------------------------------------------------------------

    def _on_map(self, msg: Any) -> None:
        self.map = OccupancyMap.from_msg(msg)
        self.costmap = Costmap.from_occupancy(self.map.data, self.map.width, self.map.height, self.map.resolution,
                                              self.map.origin[:2], **self.costmap_params)
        self.filters.attach(self.costmap)

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

        return GoalResponse.REJECT if self._busy else GoalResponse.ACCEPT

    async def _on_goal_pose(self, pose: Any) -> None:
        """bt_navigator's onGoalPoseReceived: the pose becomes a navigate_to_pose goal of our own server."""
        from aiorobot.msgs.nav2_msgs import NavigateToPose

        handle = await self._self_client.send_goal(NavigateToPose.Goal(pose=pose))
        if not handle.accepted:
            self.get_logger().warning("goal_pose: navigate_to_pose refused the goal")

    def _accept_or_preempt(self, name: str) -> Any:
        """A navigation action's goal callback: a goal of the running action preempts it (Nav2's
        SimpleActionServer: the running goal is aborted and the new one runs); others wait their turn."""

        def accept(goal: Any) -> Any:
            from aiorobot import GoalResponse

            if not self._busy:
                return GoalResponse.ACCEPT
            if self._running == name:
                self._preempt = True
                return GoalResponse.ACCEPT
            return GoalResponse.REJECT

        return accept

    def _preempting(self, name: str, action: Any, run: Any) -> Any:
        async def execute(handle: Any) -> Any:
            clock = self.get_clock()
            self._latest = token = object()
            while self._busy:  # the preempted goal ends at its next tick
                await clock.sleep_for(0.01)
            if self._latest is not token:  # a still newer goal came while this one waited
                handle.abort()
                return action.Result(error_code=NavigationFailure.UNKNOWN.code, error_msg="preempted by a newer goal")
            self._preempt, self._running = False, name
            try:
                return await run(handle)
            finally:
                self._running = ""

        return execute

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
        return result

    async def _follow_waypoints(self, handle: Any) -> Any:
        from aiorobot.msgs.nav2_msgs import FollowWaypoints, MissedWaypoint, NavigateToPose

        result = FollowWaypoints.Result()
        poses = list(handle.request.poses)
        if not poses:
            handle.abort()
            return result
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
                    except _Preempted as err:
                        handle.abort()
                        self.get_logger().warning(f"waypoint following {err}")
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
        return result

    async def _compute_path(self, handle: Any) -> Any:
        from aiorobot.msgs.nav2_msgs import ComputePathToPose

        req = handle.request
        result = ComputePathToPose.Result()
        t0 = time.perf_counter()
        try:
            await self._wait_for_map()
            if not req.use_start:
                await self._wait_for_robot_pose()  # a planner asked at start-up waits for tf, up to transform_timeout
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
        """Drive to one pose with the behaviour tree; True on arrival, False when canceled; raises _Abort with the reason."""
        from ._bt_navigator import navigate_with_tree

        return await navigate_with_tree(self, handle, target, action, nav_start, remaining=remaining, feedback=feedback)

    def _new_controller(self) -> RegulatedPurePursuit | Mppi:
        """A fresh instance of the selected controller on the current costmap."""
        if self.mppi_params is not None:
            return Mppi(self.mppi_params, self.costmap)
        return RegulatedPurePursuit(self.rpp_params, self.costmap)

    def _send(self, linear: float, angular: float, lateral: float = 0.0) -> None:
        from aiorobot.msgs.geometry_msgs import Twist, Vector3

        self.last_speed = float(math.hypot(linear, lateral))
        self.cmd_pub.publish(Twist(linear=Vector3(x=float(linear), y=float(lateral)), angular=Vector3(z=float(angular))))

    def _stop_base(self) -> None:
        self._send(0.0, 0.0)
