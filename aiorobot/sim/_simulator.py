"""``Simulator``: the node that runs a :class:`World`, a :class:`RobotBody` and the sensor models.

With ``real_time_factor = 0`` the simulator owns time: it steps the world to the
next event (a sensor due, a physics step, or the earliest deadline any sim-time
node waits for), publishes ``/clock``, publishes what is due, and lets every node
handle it before the next step. The same seed and parameters then give
bit-identical message sequences. With ``real_time_factor > 0`` the same steps are
paced against the wall clock.

With ``time_source = "system"`` (real time only: ``real_time_factor = 1``) the simulator
behaves as a robot's drivers do: it publishes no ``/clock``, and stamps every message and
transform with system time, its origin taken when its loop starts plus the elapsed sim time,
so physics stays the same per step and stamps stay monotonic; the other nodes then run on
the system clock (``use_sim_time = false``), their timers on their own deadlines.
"""

from __future__ import annotations

import asyncio
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from aiorobot import Node, Parameter, QoSProfile, compile_kernels
from aiorobot._core._qos import DurabilityPolicy

from ._camera import CameraModel, MarkerRenderer, camera_pose_matrix
from ._messages import occupancy_grid_message, odometry_message, static_transform
from ._raycast import raycast
from ._robot import RobotBody, make_kinematics
from ._sensors import ImuModel, LidarModel
from ._start import resolve_start
from ._world import World

__all__ = ["CAMERA_XYZ", "FRAMES", "IMU_XYZ", "LASER_XYZ", "TIME_SOURCES", "TOPICS", "Simulator", "SimulatorStatistics"]

_NS = 1_000_000_000
#: ``sim``: the simulator owns time (``/clock`` from zero); ``system``: stamps are system time.
TIME_SOURCES = ("sim", "system")

#: Frames the simulator names (REP 105): static ones it broadcasts on /tf_static, parent first.
FRAMES = {
    "map": "map",
    "odom": "odom",
    "base": "base_link",
    "laser": "laser",
    "imu": "imu_link",
    "camera": "camera_link",
    "camera_optical": "camera_optical_frame",
}
#: Mounts on base_link (m); base_link lies on the floor under the robot's centre.
LASER_XYZ = (0.0, 0.0, 0.20)
IMU_XYZ = (0.0, 0.0, 0.10)
CAMERA_XYZ = (0.10, 0.0, 0.25)
#: camera_link -> camera_optical_frame (x right, y down, z forward), as x, y, z, w.
OPTICAL_QUATERNION = (-0.5, 0.5, -0.5, 0.5)

#: topic -> (message type, what it carries)
TOPICS = {
    "/clock": ("rosgraph_msgs/msg/Clock", "sim time (owned by the simulator; not with time_source = system)"),
    "/odom": ("nav_msgs/msg/Odometry", "wheel odometry odom -> base_link, drifting"),
    "/joint_states": ("sensor_msgs/msg/JointState", "wheel positions (rad) and speeds (rad/s)"),
    "/imu/data": ("sensor_msgs/msg/Imu", "gyro with bias and noise, accelerometer with gravity"),
    "/scan": ("sensor_msgs/msg/LaserScan", "360 beams, 0.1-12 m, ray cast on the map"),
    "/camera/image_raw": ("sensor_msgs/msg/Image", "rgb8 640x480 with the ArUco landmarks"),
    "/camera/camera_info": ("sensor_msgs/msg/CameraInfo", "fx = fy = 500, cx = 320, cy = 240"),
    "/ground_truth/odom": ("nav_msgs/msg/Odometry", "true pose and twist in map"),
    "/map": ("nav_msgs/msg/OccupancyGrid", "the world's map (transient local)"),
    "/tf_static": ("tf2_msgs/msg/TFMessage", "base_link -> laser, imu_link, camera_link -> camera_optical_frame"),
    "/tf": ("tf2_msgs/msg/TFMessage", "odom -> base_link when publish_odom_tf is set"),
}


@dataclass(frozen=True, slots=True)
class SimulatorStatistics:
    """What :meth:`Simulator.statistics` reports: a snapshot, safe to keep and compare."""

    #: the simulator's elapsed time (ns from its start, on either time source)
    sim_time_ns: int
    #: world steps taken
    steps: int
    #: wall seconds its loop has run
    wall_elapsed_sec: float
    #: times the robot's disc met an obstacle (counted once per contact)
    collisions: int
    #: ground-truth distance the robot drove (m)
    distance_m: float
    #: velocity commands taken, and those refused (not finite)
    commands_received: int
    commands_ignored: int

    @property
    def sim_sec(self) -> float:
        return self.sim_time_ns / _NS


def _footprint(text: str) -> np.ndarray | None:
    """The ``footprint`` parameter (``"[[x, y], ...]"``) as (M, 2) vertices; None for ``"[]"``."""
    import json

    try:
        rows = json.loads(text) if text.strip() else []
        vertices = np.asarray(rows, dtype=np.float64).reshape(-1, 2) if rows else None
    except (ValueError, TypeError):
        vertices = np.zeros((0, 2))
    if vertices is not None and (len(vertices) < 3 or not np.isfinite(vertices).all()):
        raise ValueError(f"footprint: expected [] or 3 or more [x, y] points such as \"[[0.2, 0.15], [0.2, -0.15], "
                         f"[-0.2, -0.15], [-0.2, 0.15]]\", found {text!r}")
    return vertices


class _Stream:
    """One periodic output: the k-th sample is due at ``round(k / rate)`` seconds (no rounding drift)."""

    __slots__ = ("name", "rate_hz", "period_ns", "count", "next_ns")

    def __init__(self, name: str, rate_hz: float) -> None:
        self.name = name
        self.rate_hz = float(rate_hz)
        self.period_ns = round(_NS / rate_hz) if rate_hz > 0 else 0
        self.count = 1
        self.next_ns: int | None = self._at(1) if rate_hz > 0 else None

    def _at(self, k: int) -> int:
        return round(k * _NS / self.rate_hz)

    def due(self, now_ns: int) -> bool:
        if self.next_ns is None or now_ns < self.next_ns:
            return False
        while self.next_ns <= now_ns:
            self.count += 1
            self.next_ns = self._at(self.count)
        return True


class Simulator(Node):
    """A simulated robot in a 2D world with lidar, IMU, wheel odometry and a camera.

    Parameters (node parameters, all read at construction)
    ----------------------------------------------------------
    world : str
        A built-in world (``box``, ``warehouse``) or a path to a map YAML.
    start : double array
        ``[x, y, yaw]`` (m, m, rad) in map: where the robot starts; refused when its disc is
        blocked. Unset: the world's start (else the origin), or, when that is blocked or in
        unknown space (a Nav2 map), the known-free cell nearest to it, with a warning.
    robot_radius, footprint : float, str
        The robot's shape for collisions: the disc of ``robot_radius``, or with ``footprint``
        (Nav2's costmap form, ``"[[x, y], ...]"`` in base_link) that polygon; a mecanum base is a
        rectangle. The start is checked with the disc.
    robot : str
        ``mecanum`` or ``diff``; geometry from ``wheel_radius``, ``wheel_separation`` (diff),
        ``half_length`` and ``half_width`` (mecanum), as in ``aiorobot.control``.
    seed : int
        Seeds every noise model.
    real_time_factor : float
        Sim seconds per wall second; 0 runs as fast as possible and steps every node in lock-step.
    time_source : str
        ``sim`` (default): own the time, publish ``/clock``, stamp with sim time from zero.
        ``system``: stamp with system time (origin at the loop's start + elapsed sim time),
        no ``/clock``; needs ``real_time_factor = 1`` and a runtime that does not use sim time.
    duration_sec : float
        Stop the runtime after this much sim time (0: run until shut down).
    scan_rate, imu_rate, odom_rate, camera_rate, ground_truth_rate : float
        Hz; 0 turns the stream off.
    """

    def __init__(self, **kw: Any) -> None:
        super().__init__("simulator", **kw)
        p = self.declare_parameter
        world_name = p("world", "box", description="built-in world name or map YAML path", read_only=True).value
        start = p("start", Parameter.Type.DOUBLE_ARRAY, description="[x, y, yaw] start in map (unset: the world's, "
                  "or the free cell nearest it)", read_only=True).value
        robot = p("robot", "mecanum", description="drive: mecanum or diff", read_only=True).value
        seed = p("seed", 1, description="seed of every noise model", read_only=True).value
        rtf = p("real_time_factor", 1.0, description="sim s per wall s; 0 = as fast as possible",
                range=(0.0, 1000.0), read_only=True).value
        self.time_source = p("time_source", "sim", description="sim: publish /clock and stamp with sim time; system: "
                             "stamp with system time, no /clock (real_time_factor = 1 only)", read_only=True).value
        if self.time_source not in TIME_SOURCES:
            raise ValueError(f"time_source: expected one of {', '.join(map(repr, TIME_SOURCES))}, found {self.time_source!r}")
        if self.time_source == "system" and rtf != 1.0:
            raise ValueError(f"time_source = 'system' needs real_time_factor = 1 (stamps are system time, so sim time "
                             f"must pass as the wall clock does), found real_time_factor = {rtf!r}; "
                             f"use time_source = 'sim' for any other rate")
        self.duration_sec = p("duration_sec", 0.0, description="stop after this much sim time (0: never)",
                              range=(0.0, 1e9), read_only=True).value
        self.step_sec = p("step_sec", 0.01, description="longest physics step", range=(1e-4, 0.1), read_only=True).value
        geometry = dict(
            wheel_radius=p("wheel_radius", 0.05, description="m", range=(1e-3, 10.0), read_only=True).value,
            wheel_separation=p("wheel_separation", 0.3, description="m (diff)", range=(1e-3, 10.0), read_only=True).value,
            half_length=p("half_length", 0.15, description="m (mecanum)", range=(0.0, 10.0), read_only=True).value,
            half_width=p("half_width", 0.15, description="m (mecanum)", range=(0.0, 10.0), read_only=True).value,
        )
        radius = p("robot_radius", 0.22, description="collision footprint radius, m", range=(0.01, 10.0), read_only=True).value
        footprint = _footprint(p("footprint", "[]", description="collision polygon [[x, y], ...] in base_link, m "
                                 "(Nav2's costmap form; [] for the disc of robot_radius)", read_only=True).value)
        rates = {
            name: p(f"{name}_rate", default, description=f"{name} rate, Hz (0: off)", range=(0.0, 10000.0), read_only=True).value
            for name, default in (("scan", 10.0), ("imu", 100.0), ("odom", 50.0), ("camera", 15.0), ("ground_truth", 50.0))
        }
        noise = {
            name: p(name, default, description=text, range=(0.0, 1e6), read_only=True).value
            for name, default, text in (
                ("wheel_slip", 0.0, "fraction of wheel motion lost to slip"),
                ("odom_scale_error", 0.02, "relative odometry scale error"),
                ("odom_noise_std", 0.02, "relative odometry noise per step"),
                ("scan_noise_std", 0.01, "lidar range noise, m"),
                ("gyro_noise_std", 0.002, "gyro white noise, rad/s"),
                ("gyro_bias_std", 0.001, "initial gyro bias spread, rad/s"),
                ("gyro_bias_walk_std", 0.0001, "gyro bias random walk, rad/s/sqrt(s)"),
                ("accel_noise_std", 0.02, "accelerometer noise, m/s^2"),
            )
        }
        self.cmd_vel_timeout_sec = p("cmd_vel_timeout_sec", 0.5, description="stop when /cmd_vel is older (0: never)",
                                     range=(0.0, 3600.0), read_only=True).value
        accel = (
            p("max_linear_accel", 2.0, description="m/s^2", range=(1e-3, 1000.0), read_only=True).value,
            p("max_angular_accel", 4.0, description="rad/s^2", range=(1e-3, 1000.0), read_only=True).value,
        )
        self.publish_odom_tf = p("publish_odom_tf", False, description="broadcast odom -> base_link", read_only=True).value
        self.drive = p("drive", "cmd_vel", description="cmd_vel: follow /cmd_vel; serial: wheels from a simulated "
                       "motor firmware on a pty (pair with SerialMotorBridge + a base controller)", read_only=True).value
        self.port_link = p("port_link", "/tmp/aiorobot-sim-motors", description="pty symlink for drive = serial",
                           read_only=True).value
        if self.drive not in ("cmd_vel", "serial"):
            raise ValueError(f"drive: expected 'cmd_vel' or 'serial', found {self.drive!r}")
        if self.drive == "serial" and rtf == 0.0:
            raise ValueError("drive = 'serial' needs real_time_factor > 0: the pty link runs on the wall clock "
                             "and cannot be stepped in lock-step; set real_time_factor = 1.0")

        if not 0.0 <= noise["wheel_slip"] < 1.0:
            raise ValueError(f"wheel_slip: expected a fraction in [0, 1), found {noise['wheel_slip']!r}")
        self.world = World.load(world_name)
        choice = resolve_start(self.world, start, radius)
        #: the robot's start pose in map (x, y, yaw)
        self.start = choice.pose
        if choice.warning is not None:
            self.get_logger().warning(choice.warning)
        self.real_time_factor = float(rtf)
        self.seed = int(seed)
        streams = np.random.SeedSequence(self.seed).spawn(4)
        self._rng_scan, self._rng_imu, self._rng_odom, _ = (np.random.default_rng(s) for s in streams)
        self.kinematics = make_kinematics(str(robot), **geometry)
        self.robot_kind = str(robot)
        self.body = RobotBody(
            self.kinematics, self.start, radius=radius, footprint=footprint,
            max_acceleration=(accel[0], accel[0], accel[1]), wheel_slip=noise["wheel_slip"],
            odom_scale_error=noise["odom_scale_error"], odom_noise_std=noise["odom_noise_std"], rng=self._rng_odom,
        )
        self.odom_noise_std = noise["odom_noise_std"]
        self.lidar = LidarModel(noise_std=noise["scan_noise_std"])
        self.imu = ImuModel(gyro_noise_std=noise["gyro_noise_std"], gyro_bias_std=noise["gyro_bias_std"],
                            gyro_bias_walk_std=noise["gyro_bias_walk_std"], accel_noise_std=noise["accel_noise_std"],
                            rng=self._rng_imu)
        self._gyro_covariance = np.eye(3).reshape(9) * max(self.imu.gyro_noise_std, 1e-6) ** 2
        self._accel_covariance = np.eye(3).reshape(9) * max(self.imu.accel_noise_std, 1e-6) ** 2
        self.camera = CameraModel()
        self._renderer: MarkerRenderer | None = None
        self._streams = {name: _Stream(name, rate) for name, rate in rates.items()}
        self.time_ns = 0
        #: added to ``time_ns`` in every stamp: 0 on sim time, system time at the loop's start on system time
        self.stamp_origin_ns = 0
        self.steps = 0
        self.commands_received = 0
        self.commands_ignored = 0
        self._last_cmd_ns: int | None = None
        self._task: asyncio.Task[None] | None = None
        self.wall_elapsed_sec = 0.0

        from aiorobot.msgs.geometry_msgs import Twist
        from aiorobot.msgs.nav_msgs import OccupancyGrid, Odometry
        from aiorobot.msgs.rosgraph_msgs import Clock
        from aiorobot.msgs.sensor_msgs import CameraInfo, Image, Imu, JointState, LaserScan

        self._types = dict(clock=Clock, imu=Imu, scan=LaserScan, image=Image, info=CameraInfo, joints=JointState)
        # Reliable publishers connect to reliable and best-effort subscriptions alike.
        sensor = QoSProfile(depth=10)
        # on system time there is no sim time to own: no /clock publisher at all, as on a robot
        self.clock_pub = self.create_publisher(Clock, "/clock", QoSProfile(depth=1)) if self.time_source == "sim" else None
        # with drive = serial the bridge publishes /joint_states and a base controller /odom
        self.odom_pub = self.create_publisher(Odometry, "/odom", 10) if self.drive == "cmd_vel" else None
        self.joint_pub = self.create_publisher(JointState, "/joint_states", 10) if self.drive == "cmd_vel" else None
        self.imu_pub = self.create_publisher(Imu, "/imu/data", sensor)
        self.scan_pub = self.create_publisher(LaserScan, "/scan", sensor)
        self.image_pub = self.create_publisher(Image, "/camera/image_raw", sensor)
        self.info_pub = self.create_publisher(CameraInfo, "/camera/camera_info", sensor)
        self.truth_pub = self.create_publisher(Odometry, "/ground_truth/odom", 10)
        self.map_pub = self.create_publisher(
            OccupancyGrid, "/map", QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)
        )
        self.pty: Any = None
        if self.drive == "cmd_vel":
            self.create_subscription(Twist, "/cmd_vel", self.on_cmd_vel, 10)
        else:
            from aiorobot.control import PtyFirmware, SimulatedFirmware

            firmware = SimulatedFirmware(wheel_count=self.kinematics.n_wheels)
            self.pty = PtyFirmware(firmware, link_path=self.port_link, clock=lambda: self.time_ns / _NS)
        import aiorobot.tf as tf

        self._static_tf = tf.StaticTransformBroadcaster(self)
        self._tf = tf.TransformBroadcaster(self) if self.publish_odom_tf else None
        # at construction, before any loop runs: a first run after installing compiles the kernels
        # (seconds), which on a running loop is a stall the loop monitor rightly reports
        compile_kernels(self.get_logger(), self._warm_up)

    def __repr__(self) -> str:
        return f"<Simulator {self.world.name} {self.robot_kind} t={self.time_ns / _NS:.3f}s rtf={self.real_time_factor:g}>"

    # -- inputs -----------------------------------------------------------------------

    def on_cmd_vel(self, msg: Any) -> None:
        twist = (msg.linear.x, msg.linear.y, msg.angular.z)
        if not all(math.isfinite(v) for v in twist):
            self.commands_ignored += 1
            self.get_logger().warning(f"ignoring /cmd_vel with non-finite values {list(twist)}", throttle_duration_sec=1.0)
            return
        self.body.set_command(twist)
        self._last_cmd_ns = self.time_ns
        self.commands_received += 1

    # -- running --------------------------------------------------------------------

    async def on_start(self) -> None:
        runtime = self.runtime
        if self.time_source == "sim" and not runtime.use_sim_time:
            self.get_logger().warning(
                "the runtime does not use sim time: other nodes will not follow /clock; "
                "set [runtime] use_sim_time = true"
            )
        elif self.time_source == "system" and runtime.use_sim_time:
            self.get_logger().warning(
                "time_source = 'system' publishes no /clock, but the runtime uses sim time: its timers "
                "will not fire; set [runtime] use_sim_time = false"
            )
        if self.pty is not None:
            self.pty.open()
            self.pty.attach()
            self.get_logger().info(f"simulated motor firmware on {self.pty.slave_path} (linked at {self.port_link})")
        self._task = self.create_task(self._run(), name="simulator loop")

    async def on_shutdown(self) -> None:
        if self.pty is not None:
            self.pty.drain()
            self.pty.close_pty()

    async def _run(self) -> None:
        try:
            await self._loop_steps()
        except asyncio.CancelledError:
            raise
        except Exception:
            self.get_logger().error(f"the simulation loop stopped at t={self.time_ns / _NS:.3f} s", exc_info=True)
            self.runtime.shutdown()

    async def _loop_steps(self) -> None:
        runtime = self.runtime
        loop = asyncio.get_running_loop()
        if self.time_source == "system":
            self.stamp_origin_ns = self.get_clock().now().nanoseconds - self.time_ns
        self._publish_clock()
        stamp = self._stamp()
        self._publish_static(stamp)
        self.map_pub.publish(occupancy_grid_message(self.world, stamp, FRAMES["map"]))
        lockstep = self.real_time_factor == 0.0
        if lockstep:
            await runtime.settle()
        wall_start = loop.time()
        step_ns = round(self.step_sec * _NS)
        end_ns = round(self.duration_sec * _NS) if self.duration_sec > 0 else None
        while True:
            target = self.time_ns + step_ns
            for stream in self._streams.values():
                if stream.next_ns is not None and stream.next_ns < target:
                    target = stream.next_ns
            waiting = runtime.clock.next_deadline_ns() if runtime.use_sim_time else None
            if waiting is not None and self.time_ns < waiting < target:
                target = waiting
            if end_ns is not None and target > end_ns:
                target = end_ns
            if not lockstep:
                delay = wall_start + target / _NS / self.real_time_factor - loop.time()
                await asyncio.sleep(max(delay, 0.0))  # behind schedule: still let other tasks run
            self.step_to(target)
            if lockstep:
                await runtime.settle()
            self.wall_elapsed_sec = loop.time() - wall_start
            if end_ns is not None and self.time_ns >= end_ns:
                runtime.shutdown()
                return

    def _warm_up(self) -> None:
        """Load the compiled kernels and marker textures now, not on the first due sample."""
        x, y, yaw = self.body.pose
        world = self.world
        raycast(world.occupied, world.resolution, world.origin[:2], (x, y), self.lidar.angles[:1])
        raycast(world.occupied, world.resolution, world.origin[:2], (x, y), self.lidar.angles[:1], clearance=world.clearance)
        if self._streams["camera"].next_ns is not None and self._renderer is None:
            self._renderer = MarkerRenderer(self.world.landmarks, self.camera)

    def step_to(self, target_ns: int) -> None:
        """Advance the world to ``target_ns``, publish ``/clock`` and every stream that is due."""
        dt = (target_ns - self.time_ns) / _NS
        if (
            self.cmd_vel_timeout_sec > 0
            and self._last_cmd_ns is not None
            and (target_ns - self._last_cmd_ns) / _NS > self.cmd_vel_timeout_sec
        ):
            self.body.set_command((0.0, 0.0, 0.0))
            self._last_cmd_ns = None
        if self.pty is not None and self.pty.is_open:
            self.body.set_wheel_speeds(self.pty.firmware.speed_rad_s)
        self.body.step(dt, self.world)
        self.time_ns = target_ns
        if self.pty is not None and self.pty.is_open:
            self.pty.pump()  # the firmware integrates its motors to the new sim time and reports ticks
        self.steps += 1
        stamp = self._stamp()
        self._publish_clock(stamp)
        streams = self._streams
        if streams["imu"].due(target_ns):
            self._publish_imu(stamp, streams["imu"].period_ns / _NS)
        if streams["odom"].due(target_ns) and self.odom_pub is not None:
            self._publish_odom(stamp)
        if streams["ground_truth"].due(target_ns):
            self._publish_truth(stamp)
        if streams["scan"].due(target_ns):
            self._publish_scan(stamp)
        if streams["camera"].due(target_ns):
            self._publish_camera(stamp)

    # -- outputs --------------------------------------------------------------------

    def _stamp(self) -> Any:
        from aiorobot import Time

        return Time(nanoseconds=self.stamp_origin_ns + self.time_ns).to_msg()

    def _publish_clock(self, stamp: Any = None) -> None:
        if self.clock_pub is None:
            return
        msg = self._types["clock"]()
        msg.clock = self._stamp() if stamp is None else stamp
        self.clock_pub.publish(msg)

    def _publish_static(self, stamp: Any) -> None:
        base = FRAMES["base"]
        transforms = [
            static_transform(base, FRAMES["laser"], LASER_XYZ),
            static_transform(base, FRAMES["imu"], IMU_XYZ),
            static_transform(base, FRAMES["camera"], CAMERA_XYZ),
            static_transform(FRAMES["camera"], FRAMES["camera_optical"], (0.0, 0.0, 0.0), OPTICAL_QUATERNION),
        ]
        for t in transforms:
            t.header.stamp = stamp
        self._static_tf.send_transform(transforms)

    def _publish_imu(self, stamp: Any, dt_sec: float) -> None:
        body = self.body
        gyro, accel = self.imu.measure(float(body.twist[2]), body.acceleration, dt_sec)
        msg = self._types["imu"]()
        msg.header.stamp = stamp
        msg.header.frame_id = FRAMES["imu"]
        msg.orientation_covariance[0] = -1.0  # no orientation estimate (sensor_msgs/Imu convention)
        msg.angular_velocity.x, msg.angular_velocity.y, msg.angular_velocity.z = (float(v) for v in gyro)
        msg.linear_acceleration.x, msg.linear_acceleration.y, msg.linear_acceleration.z = (float(v) for v in accel)
        msg.angular_velocity_covariance = self._gyro_covariance.copy()
        msg.linear_acceleration_covariance = self._accel_covariance.copy()
        self.imu_pub.publish(msg)

    def _publish_odom(self, stamp: Any) -> None:
        body = self.body
        var = max(self.odom_noise_std, 1e-3) ** 2
        assert self.odom_pub is not None
        self.odom_pub.publish(
            odometry_message(stamp, FRAMES["odom"], FRAMES["base"], body.odom_pose, body.odom_twist,
                             (var * (1 + body.distance_m),) * 3, (var, var, var))
        )
        joints = self._types["joints"]()
        joints.header.stamp = stamp
        joints.name = list(self.kinematics.wheel_names)
        joints.position = body.wheel_positions.copy()
        joints.velocity = body.wheel_velocities.copy()
        assert self.joint_pub is not None
        self.joint_pub.publish(joints)
        if self._tf is not None:
            t = static_transform(FRAMES["odom"], FRAMES["base"], (body.odom_pose[0], body.odom_pose[1], 0.0),
                                 (0.0, 0.0, math.sin(0.5 * body.odom_pose[2]), math.cos(0.5 * body.odom_pose[2])))
            t.header.stamp = stamp
            self._tf.send_transform(t)

    def _publish_truth(self, stamp: Any) -> None:
        self.truth_pub.publish(
            odometry_message(stamp, FRAMES["map"], FRAMES["base"], self.body.pose, self.body.twist,
                             (1e-9, 1e-9, 1e-9), (1e-9, 1e-9, 1e-9))
        )

    def _publish_scan(self, stamp: Any) -> None:
        x, y, yaw = self.body.pose
        c, s = math.cos(yaw), math.sin(yaw)
        lx, ly = x + c * LASER_XYZ[0] - s * LASER_XYZ[1], y + s * LASER_XYZ[0] + c * LASER_XYZ[1]
        lidar = self.lidar
        msg = self._types["scan"]()
        msg.header.stamp = stamp
        msg.header.frame_id = FRAMES["laser"]
        msg.angle_min = lidar.angle_min
        msg.angle_increment = lidar.angle_increment
        msg.angle_max = lidar.angle_min + lidar.angle_increment * (lidar.beams - 1)
        msg.scan_time = self._streams["scan"].period_ns / _NS
        msg.range_min = lidar.range_min
        msg.range_max = lidar.range_max
        msg.ranges = lidar.measure(self.world, lx, ly, yaw, self._rng_scan)
        self.scan_pub.publish(msg)

    def camera_pose(self) -> np.ndarray:
        """``map_from_optical`` (4x4) of the camera at the robot's true pose."""
        x, y, yaw = self.body.pose
        c, s = math.cos(yaw), math.sin(yaw)
        cx, cy, cz = CAMERA_XYZ
        return camera_pose_matrix(x + c * cx - s * cy, y + s * cx + c * cy, cz, yaw)

    def _visible(self, landmark: Any, position: np.ndarray) -> bool:
        world = self.world
        dx, dy = landmark.x - position[0], landmark.y - position[1]
        distance = math.hypot(dx, dy)
        hit = raycast(world.occupied, world.resolution, world.origin[:2], (position[0], position[1]),
                      np.array([math.atan2(dy, dx)]), distance + 1.0, clearance=world.clearance)[0]
        return bool(hit >= distance - 1.5 * world.resolution)

    def _publish_camera(self, stamp: Any) -> None:
        if self._renderer is None:
            self._renderer = MarkerRenderer(self.world.landmarks, self.camera)
        image, _ = self._renderer.render(self.camera_pose(), visible=self._visible)
        cam = self.camera
        msg = self._types["image"]()
        msg.header.stamp = stamp
        msg.header.frame_id = FRAMES["camera_optical"]
        msg.height, msg.width = cam.height, cam.width
        msg.encoding = "rgb8"
        msg.step = cam.width * 3
        msg.data = image.reshape(-1)
        info = self._types["info"]()
        info.header.stamp = stamp
        info.header.frame_id = FRAMES["camera_optical"]
        info.height, info.width = cam.height, cam.width
        info.distortion_model = "plumb_bob"
        info.d = np.zeros(5)
        info.k = cam.K.reshape(9)
        info.r = np.eye(3).reshape(9)
        info.p = np.hstack([cam.K, np.zeros((3, 1))]).reshape(12)
        # the calibration first: a pipeline that needs it then has it for the very first frame
        self.info_pub.publish(info)
        self.image_pub.publish(msg)

    # -- aiorobot run / sim display -------------------------------------------------------

    def statistics(self) -> SimulatorStatistics:
        """Sim time, steps, collisions and distance so far (a frozen snapshot)."""
        body = self.body
        return SimulatorStatistics(self.time_ns, self.steps, self.wall_elapsed_sec, body.collisions, body.distance_m,
                                   self.commands_received, self.commands_ignored)

    @property
    def achieved_real_time_factor(self) -> float:
        return self.time_ns / _NS / self.wall_elapsed_sec if self.wall_elapsed_sec > 0 else 0.0

    def status_line(self) -> str:
        x, y, yaw = self.body.pose
        return (
            f"sim t={self.time_ns / _NS:.1f}s ({self.achieved_real_time_factor:.1f}x real time) "
            f"pose=({x:+.2f}, {y:+.2f}, {math.degrees(yaw):+.0f}deg) collisions={self.body.collisions}"
        )

    def summary(self) -> str:
        x, y, yaw = self.body.pose
        ex, ey, _ = self.body.odom_error(self.start)
        return (
            f"{self.get_name()}: {self.time_ns / _NS:.2f} s of sim time in {self.wall_elapsed_sec:.2f} s "
            f"({self.achieved_real_time_factor:.1f}x), {self.commands_received} cmd_vel "
            f"({self.commands_ignored} ignored), {self.body.distance_m:.2f} m driven, final pose "
            f"({x:+.3f}, {y:+.3f}, {math.degrees(yaw):+.1f} deg), odometry drift {math.hypot(ex, ey):.3f} m, "
            f"collisions {self.body.collisions}"
        )
