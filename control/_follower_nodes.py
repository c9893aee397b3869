"""Thin nodes around the go-to-goal and pure-pursuit cores: ``/odom`` in, ``/cmd_vel`` out."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

from aiorobot import Node

from ._go_to_goal import DriveCommand, GoToGoal
from ._pure_pursuit import PurePursuit

__all__ = ["GoToGoalController", "PurePursuitController", "path_from_msg", "pose_from_msg"]


def _yaw(q: Any) -> float:
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def pose_from_msg(pose: Any) -> NDArray[np.float64]:
    """``(x, y, yaw)`` of a ``geometry_msgs/Pose``."""
    return np.array([pose.position.x, pose.position.y, _yaw(pose.orientation)])


def path_from_msg(path: Any) -> NDArray[np.float64]:
    """A ``nav_msgs/Path`` as an ``(N, 3)`` array of ``(x, y, yaw)``."""
    return np.array([pose_from_msg(p.pose) for p in path.poses], dtype=np.float64).reshape(-1, 3)


class _FollowerNode(Node):
    """Shared wiring: track ``/odom``, publish ``/cmd_vel`` at ``rate_hz`` while a target is active."""

    def __init__(self, name: str, **kw: Any) -> None:
        super().__init__(name, **kw)
        rate_hz = self.declare_parameter("rate_hz", 20.0, description="command rate", range=(1.0, 1000.0)).value
        from aiorobot.msgs.geometry_msgs import Twist
        from aiorobot.msgs.nav_msgs import Odometry

        self._twist_type = Twist
        self.pose: NDArray[np.float64] | None = None
        self.odom_frame_id = ""
        self.active = False
        self.goals_reached = 0
        self.cmd_pub = self.create_publisher(Twist, "/cmd_vel", 10)
        self.create_subscription(Odometry, "/odom", self.on_odom, 10)
        self.create_timer(1.0 / rate_hz, self.on_tick)

    def on_odom(self, msg: Any) -> None:
        self.pose = pose_from_msg(msg.pose.pose)
        self.odom_frame_id = msg.header.frame_id

    def _frame_ok(self, frame_id: str, what: str) -> bool:
        if frame_id and self.odom_frame_id and frame_id != self.odom_frame_id:
            self.get_logger().warning(
                f"{what} is in frame {frame_id!r} but odometry is in {self.odom_frame_id!r}; "
                "send it in the odometry frame",
                throttle_duration_sec=5.0,
            )
            return False
        return True

    def _publish(self, linear: float, angular: float) -> None:
        msg = self._twist_type()
        msg.linear.x = float(linear)
        msg.angular.z = float(angular)
        self.cmd_pub.publish(msg)

    def _compute(self, pose: NDArray[np.float64]) -> DriveCommand:
        raise NotImplementedError

    def on_tick(self) -> None:
        if not self.active or self.pose is None:
            return
        command = self._compute(self.pose)
        self._publish(command.linear, command.angular)
        if command.done:
            self.active = False
            self.goals_reached += 1
            x, y, theta = self.pose
            self.get_logger().info(f"reached the goal at ({x:.3f}, {y:.3f}, {math.degrees(theta):.1f} deg)")

    async def on_shutdown(self) -> None:
        if self.active:
            self._publish(0.0, 0.0)


class GoToGoalController(_FollowerNode):
    """Drives to each ``/goal_pose`` (geometry_msgs/PoseStamped, odometry frame) with :class:`GoToGoal`.

    The goal's orientation is used as a final yaw when ``use_goal_yaw`` is set.

    rclpy difference: the goal must be in the odometry frame; it is not transformed
    with tf as Nav2's controllers transform their input. A goal in another frame is
    ignored with a warning naming both frames.
    """

    def __init__(self, **kw: Any) -> None:
        super().__init__("go_to_goal", **kw)
        p = self.declare_parameter
        self.controller = GoToGoal(
            k_linear=p("k_linear", 1.0, description="distance gain, 1/s").value,
            k_angular=p("k_angular", 2.0, description="heading gain, 1/s").value,
            max_linear=p("max_linear", 0.5, description="speed limit, m/s").value,
            max_angular=p("max_angular", 1.5, description="yaw rate limit, rad/s").value,
            heading_threshold_rad=p("heading_threshold_rad", 0.5, description="turn in place beyond").value,
            goal_tolerance_m=p("goal_tolerance_m", 0.05, description="goal radius, m").value,
            yaw_tolerance_rad=p("yaw_tolerance_rad", 0.05, description="final yaw tolerance").value,
        )
        self.use_goal_yaw = p("use_goal_yaw", False, description="turn to the goal's yaw at the end").value
        self.goal: NDArray[np.float64] | None = None
        from aiorobot.msgs.geometry_msgs import PoseStamped

        self.create_subscription(PoseStamped, "/goal_pose", self.on_goal, 10)

    def on_goal(self, msg: Any) -> None:
        if not self._frame_ok(msg.header.frame_id, "/goal_pose"):
            return
        pose = pose_from_msg(msg.pose)
        self.goal = pose if self.use_goal_yaw else pose[:2]
        self.active = True

    def _compute(self, pose: NDArray[np.float64]) -> DriveCommand:
        assert self.goal is not None
        return self.controller.compute(pose, self.goal)


class PurePursuitController(_FollowerNode):
    """Follows each ``/plan`` (nav_msgs/Path, odometry frame) with :class:`PurePursuit`.

    rclpy difference: the plan must be in the odometry frame; it is not transformed
    with tf as Nav2's controller server transforms the global plan. A plan in another
    frame is ignored with a warning naming both frames.
    """

    def __init__(self, **kw: Any) -> None:
        super().__init__("pure_pursuit", **kw)
        p = self.declare_parameter
        self._settings = dict(
            lookahead_m=p("lookahead_m", 0.3, description="lookahead distance, m").value,
            linear_speed=p("linear_speed", 0.3, description="cruise speed, m/s").value,
            max_angular=p("max_angular", 1.5, description="yaw rate limit, rad/s").value,
            goal_tolerance_m=p("goal_tolerance_m", 0.05, description="end-of-path radius, m").value,
        )
        self.follower: PurePursuit | None = None
        from aiorobot.msgs.nav_msgs import Path

        self.create_subscription(Path, "/plan", self.on_path, 10)

    def on_path(self, msg: Any) -> None:
        if not self._frame_ok(msg.header.frame_id, "/plan"):
            return
        points = path_from_msg(msg)
        if len(points) == 0:
            self.active = False
            self._publish(0.0, 0.0)
            return
        self.follower = PurePursuit(points, **self._settings)
        self.active = True

    def _compute(self, pose: NDArray[np.float64]) -> DriveCommand:
        assert self.follower is not None
        return self.follower.compute(pose)
