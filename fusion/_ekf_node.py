"""``EkfNode``: robot_localization's ``ekf_node`` (parameters, topics, tf) on :class:`FilterTimeline`."""

from __future__ import annotations

import math
from collections import Counter
from typing import Any

import numpy as np

from aiorobot import Node, compile_kernels
from aiorobot.tf import quaternion_from_euler

from ._ekf import STATE_SIZE, Ekf, check_covariance
from ._inputs import (
    InputConfig,
    InputRejected,
    PoseTracker,
    imu_measurements,
    pose_measurement,
    rotation_from_quaternion,
    twist_measurement,
)
from ._parameters import IGNORED_PARAMETERS, UKF_PARAMETERS, check_parameter_names, input_names
from ._timeline import FilterTimeline, Measurement

__all__ = ["EkfNode"]

_NS = 1_000_000_000


class EkfNode(Node):
    """robot_localization's ``ekf_node``: fuses ``odomN``/``imuN``/``poseN``/``twistN`` into ``odometry/filtered``.

    Parameters keep robot_localization's names and meanings (``docs/fusion.md`` has the table); an
    unknown name raises ``ValueError`` suggesting the nearest valid one. Measurements are applied at
    their header stamps in stamp order; with ``smooth_lagged_data`` a late one rewinds the filter and
    replays (``history_length``). Bad messages (NaN/inf, covariance not symmetric PSD, wrong frame,
    stamps too far ahead or too old) are rejected with a throttled warning naming the input and
    counted on ``/diagnostics`` and in :attr:`rejected`.

    rclpy difference: the filtered state is published right after each message is applied (lowest
    latency), and at ``frequency`` only while no input arrives within ``sensor_timeout``;
    robot_localization publishes at ``frequency`` only. Poses must be in ``world_frame`` and twists
    in ``base_link_frame`` (IMUs may be in any frame on tf); robot_localization transforms poses and
    twists through tf. ``toggle`` is std_srvs/SetBool and ``set_pose`` a topic only, as
    robot_localization's own service types do not exist here.
    """

    #: the other filter's own parameters: accepted with a warning that they have no effect here
    _OTHER_FILTER_PARAMETERS: tuple[str, ...] = UKF_PARAMETERS
    _OTHER_FILTER = "UkfNode's (robot_localization's ukf_node)"

    def __init__(self, name: str = "ekf_filter_node", **kw: Any) -> None:
        super().__init__(name, **kw)
        # every override, whatever its source: code, a TOML table, -p or a parameter file
        given = sorted(self.get_parameter_overrides())
        check_parameter_names(given, filter_parameters=UKF_PARAMETERS, source=self.get_parameter_override_source)
        p = self._declare_globals()
        log = self.get_logger()
        for ignored in sorted(set(given) & set(IGNORED_PARAMETERS)):
            self.declare_parameter(ignored, self._override_type_default(ignored))
            log.warning(f"robot_localization parameter {ignored!r} has no effect in aiorobot")
        for other in sorted(set(given) & set(self._OTHER_FILTER_PARAMETERS)):
            self.declare_parameter(other, self._override_type_default(other))
            log.warning(f"{other!r} is {self._OTHER_FILTER} parameter; it has no effect in {type(self).__name__}")
        #: the filter core: an :class:`Ekf` here, a :class:`Ukf` in :class:`UkfNode`
        self.filter = self._make_filter(p)
        self.timeline = FilterTimeline(
            self.filter,
            two_d_mode=p["two_d_mode"],
            smooth_lagged_data=p["smooth_lagged_data"],
            history_length_sec=p["history_length"],
        )
        self.rejected: Counter[tuple[str, str]] = Counter()
        self.received: Counter[str] = Counter()
        self.enabled = not p["disabled_at_startup"]
        self.inputs: list[InputConfig] = []
        self._trackers: dict[str, PoseTracker] = {}
        self._last_input_ns: int | None = None  # node clock (sim time on sim time), as robot_localization
        self._last_published_stamp = -math.inf
        # filter time is seconds since the first stamp seen: exact to the nanosecond for days
        self._origin_ns: int | None = None
        from aiorobot.msgs.nav_msgs import Odometry

        self._odometry_type = Odometry
        self.odom_pub = self.create_publisher(Odometry, "odometry/filtered", 10)
        self._tf = None
        self._tf_buffer = None
        # a tf listener only where transforms are read: IMUs in their own frame, map -> odom
        if any(kind == "imu" for _, kind in input_names(given)) or self.world_frame == self.map_frame:
            from aiorobot.tf import Buffer, TransformListener

            self._tf_buffer = Buffer()
            self._tf_listener = TransformListener(self._tf_buffer, self)
        if self.publish_tf:
            from aiorobot.tf import TransformBroadcaster

            self._tf = TransformBroadcaster(self)
        for input_name, kind in input_names(given):
            self._add_input(input_name, kind)
        if self.inputs:
            log.info(f"fusing {', '.join(f'{c.name} ({c.kind} on {c.topic})' for c in self.inputs)}")
        else:
            log.warning("no input given (odom0, imu0, pose0, twist0, ...): the filter has nothing to fuse")
        self._wire_services()
        self.create_timer(1.0 / self.frequency, self._on_period)
        if self.print_diagnostics:
            from aiorobot.msgs.diagnostic_msgs import DiagnosticArray

            self._diag_type = DiagnosticArray
            self.diagnostics_pub = self.create_publisher(DiagnosticArray, "/diagnostics", 10)
            self.create_timer(1.0, self.publish_diagnostics)

    @property
    def ekf(self) -> Any:
        """The filter core (:attr:`filter`), under its older name."""
        return self.filter

    # -- parameters ---------------------------------------------------------------------------
    def _override_type_default(self, name: str) -> Any:
        return None

    def _make_filter(self, p: dict[str, Any]) -> Any:
        """The filter core from the declared parameters, its kernels loaded (see :meth:`Ekf.warm_up`)."""
        compile_kernels(self.get_logger(), Ekf.warm_up)  # here, not on the priority loop at the first message
        return Ekf(
            process_noise=p["process_noise_covariance"],
            initial_covariance=p["initial_estimate_covariance"],
            initial_state=p["initial_state"],
        )

    def _declare_globals(self) -> dict[str, Any]:
        d = self.declare_parameter
        self.frequency = float(d("frequency", 30.0, description="Hz of the periodic prediction", range=(0.01, 10000.0)).value)
        self.sensor_timeout = float(d("sensor_timeout", 1.0 / self.frequency, description="s without input before predicting alone").value)
        self.map_frame = d("map_frame", "map").value
        self.odom_frame = d("odom_frame", "odom").value
        self.base_link_frame = d("base_link_frame", "base_link").value
        self.world_frame = d("world_frame", self.odom_frame).value
        if self.world_frame not in (self.map_frame, self.odom_frame):
            raise ValueError(
                f'world_frame must be map_frame "{self.map_frame}" or odom_frame "{self.odom_frame}", got "{self.world_frame}"'
            )
        self.publish_tf = bool(d("publish_tf", True).value)
        self.print_diagnostics = bool(d("print_diagnostics", True).value)
        self.future_tolerance_sec = float(d("future_tolerance_sec", 1.0, description="reject stamps further ahead").value)
        self.gravitational_acceleration = float(d("gravitational_acceleration", 9.80665).value)
        out: dict[str, Any] = {
            "two_d_mode": bool(d("two_d_mode", False).value),
            "smooth_lagged_data": bool(d("smooth_lagged_data", False).value),
            "history_length": float(d("history_length", 0.0).value),
            "disabled_at_startup": bool(d("disabled_at_startup", False).value),
        }
        from ._ekf import DEFAULT_PROCESS_NOISE

        out["process_noise_covariance"] = check_covariance(
            "process_noise_covariance", d("process_noise_covariance", DEFAULT_PROCESS_NOISE.reshape(-1).tolist()).value
        )
        out["initial_estimate_covariance"] = check_covariance(
            "initial_estimate_covariance", d("initial_estimate_covariance", [1e-9] * STATE_SIZE).value
        )
        state = np.asarray(d("initial_state", [0.0] * STATE_SIZE).value, dtype=np.float64)
        if state.shape != (STATE_SIZE,):
            raise ValueError(f"initial_state: expected {STATE_SIZE} values, got {state.size}")
        out["initial_state"] = state
        return out

    def _add_input(self, name: str, kind: str) -> None:
        d = self.declare_parameter
        topic = d(name, "").value
        config = np.asarray(d(f"{name}_config", [False] * STATE_SIZE).value, dtype=bool)
        if config.shape != (STATE_SIZE,):
            raise ValueError(f"{name}_config: expected {STATE_SIZE} booleans, got {config.size}")
        cfg = InputConfig(name, kind, topic, config)
        cfg.queue_size = int(d(f"{name}_queue_size", 10).value)
        if kind != "twist":
            cfg.differential = bool(d(f"{name}_differential", False).value)
            cfg.relative = bool(d(f"{name}_relative", False).value)
        if kind in ("odom", "imu"):
            cfg.pose_threshold = float(d(f"{name}_pose_rejection_threshold", math.inf).value)
            cfg.twist_threshold = float(d(f"{name}_twist_rejection_threshold", math.inf).value)
        if kind == "pose":
            cfg.pose_threshold = float(d(f"{name}_rejection_threshold", math.inf).value)
        if kind == "twist":
            cfg.twist_threshold = float(d(f"{name}_rejection_threshold", math.inf).value)
        if kind in ("odom", "pose"):
            d(f"{name}_pose_use_child_frame", False)
        if kind == "imu":
            cfg.acceleration_threshold = float(d(f"{name}_linear_acceleration_rejection_threshold", math.inf).value)
            cfg.remove_gravitational_acceleration = bool(d(f"{name}_remove_gravitational_acceleration", False).value)
            cfg.gravitational_acceleration = self.gravitational_acceleration
        if not topic:
            raise ValueError(f"{name}: expected a topic name, got an empty string")
        if not config.any():
            self.get_logger().warning(f"{name}_config selects no state member; every message on {topic} is rejected")
        self.inputs.append(cfg)
        self._trackers[name] = PoseTracker()
        if kind == "odom":
            from aiorobot.msgs.nav_msgs import Odometry as msg_type
        elif kind == "imu":
            from aiorobot.msgs.sensor_msgs import Imu as msg_type
        elif kind == "pose":
            from aiorobot.msgs.geometry_msgs import PoseWithCovarianceStamped as msg_type
        else:
            from aiorobot.msgs.geometry_msgs import TwistWithCovarianceStamped as msg_type
        self.create_subscription(msg_type, topic, lambda msg, cfg=cfg: self.on_message(cfg, msg), cfg.queue_size)

    def _wire_services(self) -> None:
        from aiorobot.msgs.geometry_msgs import PoseWithCovarianceStamped
        from aiorobot.msgs.std_srvs import Empty, SetBool

        self.create_subscription(PoseWithCovarianceStamped, "set_pose", self.on_set_pose, 10)
        self.create_service(Empty, "enable", self._on_enable)
        self.create_service(SetBool, "toggle", self._on_toggle)
        self.create_service(Empty, "reset", self._on_reset)

    # -- time --------------------------------------------------------------------------------
    def _sec(self, ns: int) -> float:
        if self._origin_ns is None:
            self._origin_ns = ns
        return (ns - self._origin_ns) * 1e-9

    def _stamp_sec(self, stamp: Any) -> float:
        """Filter seconds of a header stamp; a zero stamp means now."""
        ns = stamp.sec * _NS + stamp.nanosec
        return self._sec(ns if ns else self.now().nanoseconds)

    def _now_sec(self) -> float:
        return self._sec(self.now().nanoseconds)

    # -- inputs -------------------------------------------------------------------------------
    def _reject(self, cfg_name: str, reason: str) -> None:
        self.rejected[(cfg_name, reason)] += 1
        self.get_logger().warning(f"{cfg_name}: rejected a message: {reason}", throttle_duration_sec=5.0)

    def on_message(self, cfg: InputConfig, msg: Any) -> None:
        """Turn one input message into measurements and apply them at the message's stamp."""
        self.received[cfg.name] += 1
        if not self.enabled:
            return
        stamp = self._stamp_sec(msg.header.stamp)
        now = self._now_sec()
        try:
            if not cfg.uses_any:
                raise InputRejected(f"{cfg.name}_config selects no state member")
            if stamp > now + self.future_tolerance_sec:
                raise InputRejected(f"stamp more than future_tolerance_sec={self.future_tolerance_sec} s ahead of the clock")
            measurements = self._measurements(cfg, msg, stamp)
        except InputRejected as err:
            self._reject(cfg.name, str(err))
            return
        self._last_input_ns = self.now().nanoseconds
        applied = False
        for m in measurements:
            result = self.timeline.process(m)
            if result.accepted:
                applied = True
            else:
                self._reject(m.source, result.reason)
        if applied:
            self.publish_state()

    def _frame_check(self, cfg: InputConfig, frame: str, expected: str, what: str) -> None:
        if frame and frame != expected:
            raise InputRejected(f'{what} frame is "{frame}", expected "{expected}"')

    def _measurements(self, cfg: InputConfig, msg: Any, stamp: float) -> list[Measurement]:
        tracker = self._trackers[cfg.name]
        out: list[Measurement | None] = []
        if cfg.kind in ("odom", "pose"):
            pose = msg.pose
            if cfg.uses_pose:
                self._frame_check(cfg, msg.header.frame_id, self.world_frame if not cfg.differential and not cfg.relative else msg.header.frame_id, "pose")
            p, q = pose.pose.position, pose.pose.orientation
            out.append(
                pose_measurement(cfg, tracker, stamp, np.array([p.x, p.y, p.z]), np.array([q.x, q.y, q.z, q.w]), pose.covariance)
            )
        if cfg.kind in ("odom", "twist"):
            twist = msg.twist
            if cfg.uses_twist:
                frame = msg.child_frame_id if cfg.kind == "odom" else msg.header.frame_id
                self._frame_check(cfg, frame, self.base_link_frame, "twist")
            lin, ang = twist.twist.linear, twist.twist.angular
            out.append(
                twist_measurement(cfg, stamp, np.array([lin.x, lin.y, lin.z]), np.array([ang.x, ang.y, ang.z]), twist.covariance)
            )
        if cfg.kind == "imu":
            base_from_imu = None
            frame = msg.header.frame_id
            if frame and frame != self.base_link_frame:
                base_from_imu = self._rotation(self.base_link_frame, frame, cfg)
            q, w, a = msg.orientation, msg.angular_velocity, msg.linear_acceleration
            out.extend(
                imu_measurements(
                    cfg, tracker, stamp,
                    np.array([q.x, q.y, q.z, q.w]), msg.orientation_covariance,
                    np.array([w.x, w.y, w.z]), msg.angular_velocity_covariance,
                    np.array([a.x, a.y, a.z]), msg.linear_acceleration_covariance,
                    base_from_imu,
                )  # fmt: skip
            )
        return [m for m in out if m is not None]

    def _rotation(self, target: str, source: str, cfg: InputConfig) -> np.ndarray:
        from aiorobot import Time
        from aiorobot.tf import TransformException

        if self._tf_buffer is None:
            raise InputRejected(f'frame "{source}" is not "{target}" and no tf buffer is available')
        try:
            t = self._tf_buffer.lookup_transform(target, source, Time())
        except TransformException as err:
            raise InputRejected(f'no transform from "{source}" to "{target}": {err}') from None
        r = t.transform.rotation
        return rotation_from_quaternion(r.x, r.y, r.z, r.w)

    def on_set_pose(self, msg: Any) -> None:
        """robot_localization's ``set_pose``: jump to the given pose, zero velocity, forget history."""
        p, q = msg.pose.pose.position, msg.pose.pose.orientation
        from ._inputs import rpy_from_rotation

        try:
            R = rotation_from_quaternion(q.x, q.y, q.z, q.w)
            cov = np.asarray(msg.pose.covariance, dtype=np.float64).reshape(6, 6)
            if not (np.all(np.isfinite(cov)) and math.isfinite(p.x + p.y + p.z)):
                raise InputRejected("set_pose has NaN or inf")
        except InputRejected as err:
            self._reject("set_pose", str(err))
            return
        state = np.zeros(STATE_SIZE)
        state[:3] = (p.x, p.y, p.z)
        state[3:6] = rpy_from_rotation(R)
        P = np.eye(STATE_SIZE) * 1e-9
        P[:6, :6] = cov
        stamp = self._stamp_sec(msg.header.stamp)
        self.timeline.set_state(stamp, state, P, np.ones(STATE_SIZE, bool))
        for tracker in self._trackers.values():
            tracker.first = tracker.previous = None
        self.publish_state()

    def _on_enable(self, request: Any) -> Any:
        from aiorobot.msgs.std_srvs import Empty

        self.enabled = True
        return Empty.Response()

    def _on_toggle(self, request: Any) -> Any:
        from aiorobot.msgs.std_srvs import SetBool

        self.enabled = bool(request.data)
        return SetBool.Response(success=True, message="enabled" if self.enabled else "disabled")

    def _on_reset(self, request: Any) -> Any:
        from aiorobot.msgs.std_srvs import Empty

        self.timeline.reset()
        for tracker in self._trackers.values():
            tracker.first = tracker.previous = None
        return Empty.Response()

    # -- outputs ------------------------------------------------------------------------------
    def _on_period(self) -> None:
        if not (self.enabled and self.timeline.initialized):
            return
        if self._last_input_ns is None or (self.now().nanoseconds - self._last_input_ns) * 1e-9 > self.sensor_timeout:
            self.timeline.predict_to(self._now_sec())
            self.publish_state()

    def publish_state(self) -> None:
        """Publish ``odometry/filtered`` and the world -> base transform for the current state."""
        if not self.timeline.initialized:
            return
        x, P = self.filter.state, self.filter.covariance
        if not math.isfinite(float(x.sum())):  # never publish NaN: start over from the initial estimate
            self._reject("filter", "state became non-finite; reset to the initial estimate")
            self.timeline.reset()
            return
        stamp_sec = self.timeline.stamp_sec
        from aiorobot.msgs.builtin_interfaces import Time as TimeMsg

        sec, nanosec = divmod((self._origin_ns or 0) + round(stamp_sec * _NS), _NS)
        stamp = TimeMsg(sec=int(sec), nanosec=int(nanosec))
        q = quaternion_from_euler(x[3], x[4], x[5])
        msg = self._odometry_type()
        msg.header.stamp = stamp
        msg.header.frame_id = self.world_frame
        msg.child_frame_id = self.base_link_frame
        pose = msg.pose.pose
        pose.position.x, pose.position.y, pose.position.z = float(x[0]), float(x[1]), float(x[2])
        pose.orientation.x, pose.orientation.y, pose.orientation.z, pose.orientation.w = q
        msg.pose.covariance = P[:6, :6].reshape(36)
        tw = msg.twist.twist
        tw.linear.x, tw.linear.y, tw.linear.z = float(x[6]), float(x[7]), float(x[8])
        tw.angular.x, tw.angular.y, tw.angular.z = float(x[9]), float(x[10]), float(x[11])
        msg.twist.covariance = P[6:12, 6:12].reshape(36)
        self.odom_pub.publish(msg)
        if self._tf is not None and stamp_sec > self._last_published_stamp:
            self._last_published_stamp = stamp_sec
            self._send_tf(stamp, x, q)

    def _send_tf(self, stamp: Any, x: np.ndarray, q: tuple[float, float, float, float]) -> None:
        from aiorobot.msgs.geometry_msgs import TransformStamped

        t = TransformStamped()
        t.header.stamp = stamp
        if self.world_frame == self.odom_frame:
            t.header.frame_id, t.child_frame_id = self.odom_frame, self.base_link_frame
            t.transform.translation.x, t.transform.translation.y, t.transform.translation.z = (float(v) for v in x[:3])
            t.transform.rotation.x, t.transform.rotation.y, t.transform.rotation.z, t.transform.rotation.w = q
        else:
            # map -> odom = (map -> base) * (odom -> base)^-1, odom -> base from tf (robot_localization)
            from aiorobot import Time
            from aiorobot.tf import TransformException

            assert self._tf_buffer is not None
            try:
                ob = self._tf_buffer.lookup_transform(self.odom_frame, self.base_link_frame, Time())
            except TransformException as err:
                self.get_logger().warning(f"cannot publish {self.map_frame} -> {self.odom_frame}: {err}", throttle_duration_sec=5.0)
                return
            tr, rr = ob.transform.translation, ob.transform.rotation
            odom_base = np.eye(4)
            odom_base[:3, :3] = rotation_from_quaternion(rr.x, rr.y, rr.z, rr.w)
            odom_base[:3, 3] = (tr.x, tr.y, tr.z)
            map_base = np.eye(4)
            map_base[:3, :3] = rotation_from_quaternion(*q)
            map_base[:3, 3] = x[:3]
            map_odom = map_base @ np.linalg.inv(odom_base)
            from ._inputs import rpy_from_rotation

            t.header.frame_id, t.child_frame_id = self.map_frame, self.odom_frame
            t.transform.translation.x, t.transform.translation.y, t.transform.translation.z = (float(v) for v in map_odom[:3, 3])
            qm = quaternion_from_euler(*rpy_from_rotation(map_odom[:3, :3]))
            t.transform.rotation.x, t.transform.rotation.y, t.transform.rotation.z, t.transform.rotation.w = qm
        self._tf.send_transform(t)  # type: ignore[union-attr]

    def publish_diagnostics(self) -> None:
        """``/diagnostics``: one status with received/accepted/rejected counts per input and reason."""
        from aiorobot.msgs.diagnostic_msgs import DiagnosticStatus, KeyValue

        values = [KeyValue(key=f"{name} received", value=str(n)) for name, n in sorted(self.received.items())]
        values += [KeyValue(key=f"{src} accepted", value=str(n)) for src, n in sorted(self.timeline.accepted.items())]
        rejected = Counter(self.rejected)
        for key, n in self.timeline.rejected.items():
            if n:
                rejected[key] += n
        values += [KeyValue(key=f"{src} rejected: {why}", value=str(n)) for (src, why), n in sorted(rejected.items()) if n]
        total = sum(rejected.values())
        status = DiagnosticStatus(
            level=DiagnosticStatus.WARN if total else DiagnosticStatus.OK,
            name=f"{self.get_name()}: filter",
            message=f"{total} rejected" if total else "ok",
            values=values,
        )
        array = self._diag_type()
        array.header.stamp = self.now().to_msg()
        array.status = [status]
        self.diagnostics_pub.publish(array)

    def rejected_total(self) -> Counter[tuple[str, str]]:
        """Every rejection so far: message checks plus filter (Mahalanobis, lagged) rejections."""
        total = Counter(self.rejected)
        for key, n in self.timeline.rejected.items():
            if n:
                total[key] += n
        return total
