"""A /cmd_vel source for demos: drives a holonomic base round a square without turning.

Used by ``mecanum_serial.toml`` (``use = "square_cmd_vel:SquareCmdVel"``; ``aiorobot
run`` puts this folder on the import path).
"""

from __future__ import annotations

from typing import Any

from aiorobot import Node
from aiorobot.msgs.geometry_msgs import Twist

__all__ = ["SquareCmdVel", "main"]

# forward, left, backward, right: one side each
_SIDES = ((1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0))


class SquareCmdVel(Node):
    """Publishes ``/cmd_vel`` at ``rate_hz``: ``speed`` m/s along each side of a square for ``side_sec`` s.

    With ``strafe = false`` it drives forward and turns 90 degrees on the spot
    instead (for a differential drive), taking ``turn_sec`` for each turn.
    """

    def __init__(self, **kw: Any) -> None:
        super().__init__("square_cmd_vel", **kw)
        p = self.declare_parameter
        self.speed = p("speed", 0.3, description="speed along a side, m/s", range=(0.0, 5.0)).value
        self.side_sec = p("side_sec", 1.0, description="time per side", range=(0.05, 600.0)).value
        self.strafe = p("strafe", True, description="holonomic square (no turning)").value
        self.turn_sec = p("turn_sec", 1.0, description="time per 90-degree turn when not strafing", range=(0.05, 600.0)).value
        rate_hz = p("rate_hz", 20.0, description="publication rate", range=(1.0, 1000.0)).value
        self.pub = self.create_publisher(Twist, "/cmd_vel", 10)
        self.period_sec = 1.0 / rate_hz
        self.elapsed_sec = 0.0
        self.sent = 0
        self.create_timer(self.period_sec, self.tick)

    def command_at(self, t_sec: float) -> Twist:
        msg = Twist()
        if self.strafe:
            x, y = _SIDES[int(t_sec // self.side_sec) % 4]
            msg.linear.x, msg.linear.y = x * self.speed, y * self.speed
            return msg
        phase = t_sec % (self.side_sec + self.turn_sec)
        if phase < self.side_sec:
            msg.linear.x = self.speed
        else:
            msg.angular.z = 1.5707963267948966 / self.turn_sec
        return msg

    def tick(self) -> None:
        self.pub.publish(self.command_at(self.elapsed_sec))
        self.elapsed_sec += self.period_sec
        self.sent += 1


def main() -> None:
    """Run as a script: print the square it drives, and how to drive a simulated base with it."""
    node = SquareCmdVel()
    print(f"SquareCmdVel publishes geometry_msgs/Twist on {node.pub.topic_name} every {node.period_sec:g} s:")
    total = 4 * (node.side_sec + (0.0 if node.strafe else node.turn_sec))
    steps = 8
    for i in range(steps + 1):
        t = total * i / steps
        msg = node.command_at(t)
        print(f"  t={t:5.2f} s  linear.x={msg.linear.x:+.2f} linear.y={msg.linear.y:+.2f} angular.z={msg.angular.z:+.2f}")
    print("Drive a simulated mecanum base with it: aiorobot run examples/mecanum_serial.toml --duration 5")


if __name__ == "__main__":
    main()
