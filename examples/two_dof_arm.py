"""A two-DOF arm: robot state publisher + swept joint states + a tf listener.

    python examples/two_dof_arm.py

The RobotStatePublisher reads ``examples/urdf/two_dof_arm.urdf``, publishes its
fixed joints on /tf_static and the shoulder and elbow joints on /tf from the
JointState messages a sweeping node publishes on /joint_states. A listener fills
a Buffer, and the tool tip is printed in base_link coordinates.
"""

from __future__ import annotations

import math
from pathlib import Path

import aiorobot
from aiorobot import Node, Runtime, Time
from aiorobot.msgs.sensor_msgs import JointState
from aiorobot.tf import Buffer, LookupException, RobotStatePublisher, TransformListener

URDF = Path(__file__).resolve().parent / "urdf" / "two_dof_arm.urdf"


class JointSweep(Node):
    """Publishes shoulder and elbow angles following slow sine waves, at 50 Hz."""

    def __init__(self, **kw):
        super().__init__("joint_sweep", **kw)
        self.pub = self.create_publisher(JointState, "/joint_states", 10)
        self.create_timer(0.02, self.tick)

    def tick(self) -> None:
        now = self.now()
        t = now.nanoseconds / 1e9
        msg = JointState(name=["shoulder_joint", "elbow_joint"], position=[math.sin(t), 0.8 * math.sin(2 * t)])
        msg.header.stamp = now.to_msg()
        self.pub.publish(msg)


class ToolPrinter(Node):
    """Looks the tool tip up in base_link five times a second."""

    def __init__(self, **kw):
        super().__init__("tool_printer", **kw)
        self.buffer = Buffer()
        self.listener = TransformListener(self.buffer, self)
        self.create_timer(0.2, self.tick)

    async def tick(self) -> None:
        try:
            tip = await self.buffer.lookup_transform_async("base_link", "tool0", Time(), timeout_sec=0.1)
        except LookupException as exc:
            self.get_logger().info(f"waiting for transforms: {exc}", throttle_duration_sec=1.0)
            return
        p = tip.transform.translation
        print(f"tool0 in base_link: x={p.x:+.3f} y={p.y:+.3f} z={p.z:+.3f} m")


async def main() -> None:
    async with Runtime() as rt:
        rt.add_node(RobotStatePublisher(parameter_overrides={"robot_description_file": str(URDF)}))
        rt.add_node(JointSweep())
        rt.add_node(ToolPrinter())
        await rt.spin(duration_sec=3.0)


if __name__ == "__main__":
    aiorobot.run(main())
