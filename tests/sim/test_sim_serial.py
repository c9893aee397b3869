"""drive = serial: /cmd_vel -> MecanumController -> SerialMotorBridge -> pty -> simulated firmware -> the robot."""

from __future__ import annotations

import asyncio
from pathlib import Path

import pytest

from aiorobot import Node, Runtime
from aiorobot.control import MecanumController, SerialMotorBridge
from aiorobot.msgs.geometry_msgs import Twist
from aiorobot.msgs.nav_msgs import Odometry
from aiorobot.sim import Simulator


async def test_serial_drive_moves_the_robot_through_the_firmware_on_a_pty(tmp_path: Path) -> None:
    link = str(tmp_path / "motors")
    async with Runtime(use_sim_time=True, handle_signals=False) as rt:
        sim = rt.add_node(Simulator(parameter_overrides={
            "drive": "serial", "port_link": link, "real_time_factor": 1.0, "camera_rate": 0.0}))
        rt.add_node(SerialMotorBridge(parameter_overrides={"port": link}))
        rt.add_node(MecanumController(parameter_overrides={"publish_tf": False}))
        driver = rt.add_node(Node("driver"))
        pub = driver.create_publisher(Twist, "/cmd_vel", 10)
        odom: list[Odometry] = []
        driver.create_subscription(Odometry, "/odom", odom.append, 10)

        def tick() -> None:
            msg = Twist()
            msg.linear.x = 0.3
            pub.publish(msg)

        driver.create_timer(0.05, tick)
        async with asyncio.timeout(40):
            while sim.body.pose[0] < 0.2 or not odom or odom[-1].pose.pose.position.x < 0.1:
                await asyncio.sleep(0.05)
        assert sim.pty.firmware.commands_received > 0
        assert abs(sim.body.pose[1]) < 0.05
        assert sim.commands_received == 0  # the simulator itself did not read /cmd_vel


def test_serial_drive_refuses_lock_step() -> None:
    with pytest.raises(ValueError, match=r"drive = 'serial' needs real_time_factor > 0"):
        Simulator(parameter_overrides={"drive": "serial", "real_time_factor": 0.0})
