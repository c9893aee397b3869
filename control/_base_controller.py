"""Base controller nodes: ``/cmd_vel`` in, wheel commands out, wheel feedback in, ``/odom`` out.

The node is a thin shell around the pure cores: :class:`VelocitySmoother` for
limits, the drive's inverse kinematics plus :func:`saturate_wheel_speeds` for the
wheel commands, :class:`WheelOdometry` for odometry. Meant for the priority loop.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

from aiorobot import Node
from aiorobot.lowlevel import add_emergency_stop, remove_emergency_stop

from ._kinematics import DiffDrive, Kinematics, Mecanum, saturate_wheel_speeds
from ._odometry import WheelOdometry
from ._smoother import VelocitySmoother

__all__ = ["BaseController", "DiffDriveController", "MecanumController", "odometry_message"]

_NS_PER_SEC = 1_000_000_000


def odometry_message(
    odometry: WheelOdometry,
    stamp: Any,
    frame_id: str,
    child_frame_id: str,
    twist_variance: tuple[float, float, float] = (1e-3, 1e-3, 1e-3),
) -> Any:
    """A ``nav_msgs/Odometry`` for the state of ``odometry``.

    The 3x3 ``(x, y, yaw)`` covariance fills the rows and columns 0, 1 and 5 of
    the 6x6 pose covariance; z, roll and pitch get a small fixed variance (a
    planar base does not move in them).
    """
    from aiorobot.msgs.nav_msgs import Odometry

    msg = Odometry()
    msg.header.stamp = stamp
    msg.header.frame_id = frame_id
    msg.child_frame_id = child_frame_id
    x, y, theta = odometry.pose
    msg.pose.pose.position.x = float(x)
    msg.pose.pose.position.y = float(y)
    msg.pose.pose.orientation.z = math.sin(0.5 * theta)
    msg.pose.pose.orientation.w = math.cos(0.5 * theta)
    pose_cov = np.zeros((6, 6))
    pose_cov[2, 2] = pose_cov[3, 3] = pose_cov[4, 4] = 1e-6
    index = [0, 1, 5]
    pose_cov[np.ix_(index, index)] = odometry.covariance
    msg.pose.covariance = pose_cov.reshape(36)
    vx, vy, omega = odometry.twist
    msg.twist.twist.linear.x = float(vx)
    msg.twist.twist.linear.y = float(vy)
    msg.twist.twist.angular.z = float(omega)
    twist_cov = np.diag([twist_variance[0], twist_variance[1], 1e-6, 1e-6, 1e-6, twist_variance[2]])
    msg.twist.covariance = twist_cov.reshape(36)
    return msg


class BaseController(Node):
    """Common node logic; use :class:`DiffDriveController` or :class:`MecanumController`.

    Topics: subscribes ``/cmd_vel`` (geometry_msgs/Twist) and ``/joint_states``
    (sensor_msgs/JointState: wheel positions in rad, or velocities in rad/s);
    publishes ``/wheel_commands`` (sensor_msgs/JointState with ``velocity`` in
    rad/s) and ``/odom`` (nav_msgs/Odometry), and ``odom -> base_link`` on
    ``/tf`` when ``publish_tf`` is set and ``aiorobot.tf`` has a ``TransformBroadcaster``.

    Watchdog: when no ``/cmd_vel`` arrived for ``cmd_timeout_sec`` the wheel
    commands drop to zero at once (no ramp: the command source is gone) and a
    throttled warning is logged. On shutdown a zero wheel command is published.
    """

    def __init__(self, name: str, **kw: Any) -> None:
        super().__init__(name, **kw)
        self.kinematics = self._make_kinematics()
        p = self.declare_parameter
        names = p(
            "joint_names",
            list(self.kinematics.wheel_names),
            description="wheel joints, in kinematic order",
            read_only=True,
        ).value
        if len(names) != self.kinematics.n_wheels:
            raise ValueError(
                f"joint_names must name {self.kinematics.n_wheels} wheels for {type(self.kinematics).__name__}, "
                f"got {len(names)}: {list(names)!r}"
            )
        self.joint_names = [str(n) for n in names]
        self.max_wheel_speed = p("max_wheel_speed", 30.0, description="wheel speed limit, rad/s", range=(1e-3, 1e4)).value
        max_velocity = [
            p("max_linear_x", 1.0, description="forward speed limit, m/s", range=(1e-3, 100.0)).value,
            p("max_linear_y", 1.0, description="sideways speed limit, m/s (mecanum)", range=(1e-3, 100.0)).value,
            p("max_angular_z", 2.0, description="yaw rate limit, rad/s", range=(1e-3, 100.0)).value,
        ]
        max_accel = [
            p("max_accel_x", 2.0, description="forward acceleration limit, m/s^2", range=(1e-3, 1000.0)).value,
            p("max_accel_y", 2.0, description="sideways acceleration limit, m/s^2", range=(1e-3, 1000.0)).value,
            p("max_accel_angular", 4.0, description="yaw acceleration limit, rad/s^2", range=(1e-3, 1000.0)).value,
        ]
        self.smoother = VelocitySmoother(max_velocity, max_accel)
        self.cmd_timeout_sec = p(
            "cmd_timeout_sec", 0.5, description="zero the wheels when /cmd_vel is older", range=(1e-3, 3600.0)
        ).value
        self.rate_hz = p("rate_hz", 50.0, description="wheel command rate", range=(1.0, 1000.0), read_only=True).value
        self.odom_frame_id = p("odom_frame_id", "odom", description="odometry frame", read_only=True).value
        self.base_frame_id = p("base_frame_id", "base_link", description="robot base frame", read_only=True).value
        self.publish_tf = p("publish_tf", True, description="broadcast odom -> base_link", read_only=True).value
        self.odometry = WheelOdometry(self.kinematics)
        self.target = np.zeros(3)
        self.wheel_command: NDArray[np.float64] = np.zeros(self.kinematics.n_wheels)
        self.timed_out = True
        self.watchdog_trips = 0
        self.commands_received = 0
        self.feedback_received = 0
        self._last_cmd_ns: int | None = None
        self._last_tick_ns: int | None = None
        self._tf_broadcaster: Any = None

        from aiorobot.msgs.geometry_msgs import Twist
        from aiorobot.msgs.nav_msgs import Odometry
        from aiorobot.msgs.sensor_msgs import JointState

        self._joint_state_type = JointState
        self.wheel_pub = self.create_publisher(JointState, "/wheel_commands", 10)
        self.odom_pub = self.create_publisher(Odometry, "/odom", 10)
        self.create_subscription(Twist, "/cmd_vel", self.on_cmd_vel, 10)
        self.create_subscription(JointState, "/joint_states", self.on_joint_states, 10)
        self.timer = self.create_timer(1.0 / self.rate_hz, self.on_tick)
        self.add_on_set_parameters_callback(self._on_set_parameters)
        if self.publish_tf:
            import aiorobot.tf as tf

            broadcaster = getattr(tf, "TransformBroadcaster", None)
            if broadcaster is not None:
                self._tf_broadcaster = broadcaster(self)

    def _make_kinematics(self) -> Kinematics:
        raise NotImplementedError("subclasses build their kinematics")


    _LIMITS = {
        "max_linear_x": ("max_velocity", 0),
        "max_linear_y": ("max_velocity", 1),
        "max_angular_z": ("max_velocity", 2),
        "max_accel_x": ("max_acceleration", 0),
        "max_accel_y": ("max_acceleration", 1),
        "max_accel_angular": ("max_acceleration", 2),
    }

    def _on_set_parameters(self, parameters: list[Any]) -> Any:
        """Limits, ``max_wheel_speed`` and ``cmd_timeout_sec`` change live; the rest is read-only."""
        from aiorobot import SetParametersResult

        for parameter in parameters:
            if parameter.name in self._LIMITS:
                array_name, axis = self._LIMITS[parameter.name]
                getattr(self.smoother, array_name)[axis] = float(parameter.value)
                if array_name == "max_acceleration":
                    self.smoother.max_deceleration[axis] = float(parameter.value)
            elif parameter.name == "max_wheel_speed":
                self.max_wheel_speed = float(parameter.value)
            elif parameter.name == "cmd_timeout_sec":
                self.cmd_timeout_sec = float(parameter.value)
        return SetParametersResult(successful=True)

    # -- command path ------------------------------------------------------------------

    def _target_from_twist(self, msg: Any) -> NDArray[np.float64]:
        return np.array([msg.linear.x, msg.linear.y, msg.angular.z], dtype=np.float64)

    def on_cmd_vel(self, msg: Any) -> None:
        target = self._target_from_twist(msg)
        if not np.all(np.isfinite(target)):
            self.get_logger().warning(f"ignoring /cmd_vel with non-finite values {target.tolist()}", throttle_duration_sec=1.0)
            return
        self.target = target
        self._last_cmd_ns = self.now().nanoseconds
        self.commands_received += 1
        if self.timed_out:
            self.timed_out = False

    def on_tick(self) -> None:
        now_ns = self.now().nanoseconds
        dt = 0.0 if self._last_tick_ns is None else max((now_ns - self._last_tick_ns) / _NS_PER_SEC, 0.0)
        self._last_tick_ns = now_ns
        stale = self._last_cmd_ns is None or (now_ns - self._last_cmd_ns) / _NS_PER_SEC > self.cmd_timeout_sec
        if stale:
            if not self.timed_out:
                self.timed_out = True
                self.watchdog_trips += 1
            if self._last_cmd_ns is not None:
                self.get_logger().warning(
                    f"no /cmd_vel for more than cmd_timeout_sec={self.cmd_timeout_sec} s: stopping the wheels",
                    throttle_duration_sec=5.0,
                )
            # a watchdog stop is immediate, not a ramp: the command source is gone
            self.target = np.zeros(3)
            self.smoother.reset()
        body = self.smoother.update(self.target, dt)
        wheels = self.kinematics.wheel_speeds(body)
        self.wheel_command = saturate_wheel_speeds(wheels, self.max_wheel_speed)
        self._publish_wheels(self.wheel_command)

    def _publish_wheels(self, wheels: NDArray[np.float64]) -> None:
        msg = self._joint_state_type()
        msg.header.stamp = self.now().to_msg()
        msg.name = list(self.joint_names)
        msg.velocity = np.asarray(wheels, dtype=np.float64).copy()
        self.wheel_pub.publish(msg)

    async def on_start(self) -> None:
        add_emergency_stop(self.runtime, self.get_fully_qualified_name(), self._emergency_stop)

    def _emergency_stop(self) -> None:
        """On SIGINT/SIGTERM, before anything else: publish zero wheel speeds.

        Runs in the runtime's watchdog thread, so a callback blocking this node's loop
        cannot delay it (publishing is thread-safe).
        """
        self.target = np.zeros(3)
        self._publish_wheels(np.zeros(self.kinematics.n_wheels))

    async def on_shutdown(self) -> None:
        remove_emergency_stop(self.runtime, self._emergency_stop)
        self.target = np.zeros(3)
        self.smoother.reset()
        self.wheel_command = np.zeros(self.kinematics.n_wheels)
        self._publish_wheels(self.wheel_command)

    # -- feedback path -----------------------------------------------------------------

    def on_joint_states(self, msg: Any) -> None:
        names = list(msg.name)
        try:
            index = [names.index(n) for n in self.joint_names]
        except ValueError:
            return  # not our wheels
        stamp_ns = msg.header.stamp.sec * _NS_PER_SEC + msg.header.stamp.nanosec
        if stamp_ns == 0:
            stamp_ns = self.now().nanoseconds
        stamp_sec = stamp_ns / _NS_PER_SEC
        position = np.asarray(msg.position, dtype=np.float64)
        velocity = np.asarray(msg.velocity, dtype=np.float64)
        if len(position) == len(names):
            self.odometry.update_from_wheel_positions(position[index], stamp_sec)
            if len(velocity) == len(names):
                self.odometry.twist = self.kinematics.body_twist(velocity[index])
        elif len(velocity) == len(names):
            last = getattr(self, "_last_velocity_stamp_sec", None)
            dt = 0.0 if last is None else max(stamp_sec - last, 0.0)
            self._last_velocity_stamp_sec = stamp_sec
            self.odometry.update_from_wheel_speeds(velocity[index], dt)
        else:
            return
        self.feedback_received += 1
        self._publish_odometry(msg.header.stamp if stamp_ns else self.now().to_msg())

    def _publish_odometry(self, stamp: Any) -> None:
        if stamp.sec == 0 and stamp.nanosec == 0:
            stamp = self.now().to_msg()
        self.odom_pub.publish(odometry_message(self.odometry, stamp, self.odom_frame_id, self.base_frame_id))
        if self._tf_broadcaster is not None:
            from aiorobot.msgs.geometry_msgs import TransformStamped

            t = TransformStamped()
            t.header.stamp = stamp
            t.header.frame_id = self.odom_frame_id
            t.child_frame_id = self.base_frame_id
            x, y, theta = self.odometry.pose
            t.transform.translation.x = float(x)
            t.transform.translation.y = float(y)
            t.transform.rotation.z = math.sin(0.5 * theta)
            t.transform.rotation.w = math.cos(0.5 * theta)
            self._tf_broadcaster.send_transform(t)

    # -- aiorobot run display ---------------------------------------------------------

    def status_line(self) -> str:
        x, y, theta = self.odometry.pose
        vx, vy, omega = self.odometry.twist
        return (
            f"odom x={x:+.2f} y={y:+.2f} yaw={math.degrees(theta):+.0f}deg "
            f"v=({vx:+.2f}, {vy:+.2f}, {omega:+.2f})"
        )

    def summary(self) -> str:
        x, y, theta = self.odometry.pose
        return (
            f"{self.get_name()}: {self.commands_received} cmd_vel, {self.feedback_received} wheel feedback, "
            f"{self.odometry.distance_m:.2f} m travelled, final odom ({x:+.3f}, {y:+.3f}, "
            f"{math.degrees(theta):+.1f} deg), watchdog stops {self.watchdog_trips}"
        )


class DiffDriveController(BaseController):
    """Differential-drive base controller (see :class:`BaseController`).

    Geometry parameters: ``wheel_radius`` (m), ``wheel_separation`` (m). ``linear.y`` of
    ``/cmd_vel`` is ignored. Wheel order: left, right.
    """

    def __init__(self, **kw: Any) -> None:
        super().__init__("diff_drive_controller", **kw)

    def _make_kinematics(self) -> Kinematics:
        r = self.declare_parameter("wheel_radius", 0.05, description="wheel radius, m", read_only=True).value
        s = self.declare_parameter("wheel_separation", 0.3, description="distance between the wheels, m", read_only=True).value
        return DiffDrive(r, s)

    def _target_from_twist(self, msg: Any) -> NDArray[np.float64]:
        return np.array([msg.linear.x, 0.0, msg.angular.z], dtype=np.float64)


class MecanumController(BaseController):
    """Mecanum base controller (see :class:`BaseController`).

    Geometry parameters: ``wheel_radius``, ``half_length`` (centre to axle), ``half_width``
    (centre to wheel), all in m. Wheel order: front-left, front-right, rear-left, rear-right.
    """

    def __init__(self, **kw: Any) -> None:
        super().__init__("mecanum_controller", **kw)

    def _make_kinematics(self) -> Kinematics:
        r = self.declare_parameter("wheel_radius", 0.05, description="wheel radius, m", read_only=True).value
        a = self.declare_parameter("half_length", 0.15, description="half the wheelbase, m", read_only=True).value
        b = self.declare_parameter("half_width", 0.15, description="half the track width, m", read_only=True).value
        return Mecanum(r, a, b)
