"""The robot state publisher node: URDF + joint states -> /tf and /tf_static.

As ROS 2's ``robot_state_publisher``: fixed joints go once to ``/tf_static``
(stamped with the start time); revolute, continuous and prismatic joints are
published on ``/tf`` from ``sensor_msgs/JointState`` on ``joint_states``,
stamped with the joint state's stamp and at most ``publish_frequency`` times a
second per joint. Mimic joints follow the joint they mimic.

Parameters: ``robot_description`` (URDF text) or ``robot_description_file`` (a
path, used when the text is empty), ``publish_frequency`` (Hz, 0 = no limit),
``ignore_timestamp`` (stamp with the node's clock and never rate limit),
``frame_prefix`` (prepended to every frame id). Setting ``robot_description``
while running re-reads the model; a malformed one is rejected with the reason.
"""

from __future__ import annotations

import math
from typing import Any

from aiorobot._core._node import Node
from aiorobot._core._parameter_types import Parameter, SetParametersResult
from aiorobot._core._qos import DurabilityPolicy, QoSProfile, qos_profile_sensor_data

from ._broadcasters import StaticTransformBroadcaster, TransformBroadcaster
from ._msgs import make_transform_stamped, time_ns
from ._urdf import URDFError, UrdfJoint, UrdfModel, load_urdf, parse_urdf

__all__ = ["RobotStatePublisher"]

_DESCRIPTION_QOS = QoSProfile(durability=DurabilityPolicy.TRANSIENT_LOCAL, depth=1)


class RobotStatePublisher(Node):
    """Publishes a robot's link transforms from its URDF and its joint states.

    Raises
    ------
    URDFError
        At construction, when neither parameter gives a description or the
        description is malformed (the message names the problem).
    """

    def __init__(self, name: str = "robot_state_publisher", **kw: Any) -> None:
        super().__init__(name, **kw)
        self.declare_parameter("robot_description", "", description="the robot's URDF, as XML text")
        self.declare_parameter(
            "robot_description_file", "", description="path to a URDF file, read when robot_description is empty"
        )
        self.declare_parameter(
            "publish_frequency", 20.0, description="maximum rate of /tf per joint, Hz (0: no limit)", range=(0.0, 10000.0)
        )
        self.declare_parameter(
            "ignore_timestamp", False, description="stamp joint transforms with the node's clock, never rate limit"
        )
        self.declare_parameter("frame_prefix", "", description="prepended to every published frame id")
        self.model: UrdfModel = self._load_model()
        self.description_text = self._description_text

        from aiorobot.msgs.sensor_msgs import JointState
        from aiorobot.msgs.std_msgs import String

        self._string = String
        self._static = StaticTransformBroadcaster(self)
        self._dynamic = TransformBroadcaster(self)
        self._description_pub = self.create_publisher(String, "robot_description", _DESCRIPTION_QOS)
        self.create_subscription(JointState, "joint_states", self._on_joint_states, qos_profile_sensor_data)
        self._last_publish_ns: dict[str, int] = {}
        self._last_callback_ns = 0
        self._running = False
        self.add_on_set_parameters_callback(self._on_set_parameters)

    # -- the model ---------------------------------------------------------------------

    def _load_model(self) -> UrdfModel:
        text = self.get_parameter("robot_description").value
        path = self.get_parameter("robot_description_file").value
        if text:
            self._description_text = text
            return parse_urdf(text, source=f"{self.get_fully_qualified_name()} parameter robot_description")
        if path:
            model = load_urdf(path)
            with open(path, encoding="utf-8") as f:
                self._description_text = f.read()
            return model
        raise URDFError(
            f"{self.get_fully_qualified_name()}: no robot description; set the robot_description parameter "
            "(URDF text) or robot_description_file (a path to a .urdf file)"
        )

    def _on_set_parameters(self, params: list[Parameter]) -> SetParametersResult:
        for p in params:
            if p.name == "robot_description" and p.value:
                try:
                    model = parse_urdf(p.value, source=f"{self.get_fully_qualified_name()} parameter robot_description")
                except URDFError as exc:
                    return SetParametersResult(False, str(exc))
                self.model = model
                self.description_text = p.value
                self._last_publish_ns.clear()
                if self._running:
                    self._publish_fixed()
        return SetParametersResult(True)

    # -- publishing --------------------------------------------------------------------

    async def on_start(self) -> None:
        self._running = True
        self._publish_fixed()

    def _frame(self, link: str) -> str:
        return f"{self.get_parameter('frame_prefix').value}{link}"

    def _joint_transform(self, joint: UrdfJoint, position: float, stamp_ns: int) -> Any:
        t, q = joint.transform(position)
        return make_transform_stamped(self._frame(joint.parent), self._frame(joint.child), stamp_ns, t, q)

    def _publish_fixed(self) -> None:
        now_ns = self.now().nanoseconds
        fixed = [self._joint_transform(j, 0.0, now_ns) for j in self.model.fixed_joints]
        if fixed:
            self._static.send_transform(fixed)
        self._description_pub.publish(self._string(data=self.description_text))

    def _on_joint_states(self, msg: Any) -> None:
        log = self.get_logger()
        names = list(msg.name)
        positions = list(msg.position)
        if len(names) != len(positions):
            if not positions:
                log.warning(
                    f"ignored a JointState about joint(s) {', '.join(names)} whose position member is empty",
                    throttle_duration_sec=10.0,
                )
            else:
                log.error(
                    f"ignored an invalid JointState: {len(names)} names but {len(positions)} positions",
                    throttle_duration_sec=10.0,
                )
            return
        now_ns = self.now().nanoseconds
        if self._last_callback_ns > now_ns:
            log.warning("moved backwards in time, re-publishing joint transforms")
            self._last_publish_ns.clear()
        self._last_callback_ns = now_ns

        ignore_timestamp = bool(self.get_parameter("ignore_timestamp").value)
        stamp_ns = now_ns if ignore_timestamp else time_ns(msg.header.stamp)
        frequency = float(self.get_parameter("publish_frequency").value)
        interval_ns = round(1e9 / frequency) if frequency > 0 else 0
        least_recent = min((self._last_publish_ns.get(n, 0) for n in names), default=0)
        if not ignore_timestamp and stamp_ns < least_recent + interval_ns:
            return

        joints = self.model.joints
        values: dict[str, float] = {}
        for name, position in zip(names, positions):
            joint = joints.get(name)
            if joint is None:
                log.warning(
                    f'joint state with name "{name}" was received but not found in the URDF '
                    f"(robot {self.model.name!r})",
                    throttle_duration_sec=10.0,
                )
                continue
            position = float(position)
            if not math.isfinite(position):
                log.warning(f'joint state for "{name}" is not finite ({position}); skipped', throttle_duration_sec=10.0)
                continue
            values[name] = position
        for joint in joints.values():
            if joint.mimic is not None and joint.mimic.joint in values:
                values.setdefault(joint.name, values[joint.mimic.joint] * joint.mimic.multiplier + joint.mimic.offset)
        transforms = [
            self._joint_transform(joints[name], value, stamp_ns)
            for name, value in values.items()
            if joints[name].is_moving
        ]
        if transforms:
            self._dynamic.send_transform(transforms)
        for name in names:
            self._last_publish_ns[name] = stamp_ns

