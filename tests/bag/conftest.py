"""Shared by the bag tests: ``ekf_run``, a recorded simulator run with EkfNode (recorded once per session)."""

from __future__ import annotations

import asyncio
from pathlib import Path

import pytest

from aiorobot import Node, Runtime
from aiorobot.bag import Recorder
from aiorobot.fusion import EkfNode
from aiorobot.msgs.geometry_msgs import Twist

_OFF = [False] * 6
#: EkfNode's parameters in the recorded run: wheel odometry twist and IMU yaw rate, as the demo's local filter
EKF = {
    "frequency": 50.0,
    "sensor_timeout": 0.1,
    "two_d_mode": True,
    "odom0": "/odom",
    "odom0_config": _OFF + [True, True, False, False, False, True] + [False] * 3,
    "imu0": "/imu/data",
    "imu0_config": _OFF + [False] * 5 + [True] + [False] * 3,
    "imu0_remove_gravitational_acceleration": True,
    "smooth_lagged_data": True,
    "history_length": 1.0,
}
#: the same as a ROS 2 parameter file
PARAMS_YAML = """\
/**:
  ros__parameters:
    frequency: 50.0
    sensor_timeout: 0.1
    two_d_mode: true
    odom0: /odom
    odom0_config: [false, false, false, false, false, false, true, true, false, false, false, true, false, false, false]
    imu0: /imu/data
    imu0_config: [false, false, false, false, false, false, false, false, false, false, false, true, false, false, false]
    imu0_remove_gravitational_acceleration: true
    smooth_lagged_data: true
    history_length: 1.0
"""


class _Driver(Node):
    def __init__(self) -> None:
        super().__init__("driver")
        self.pub = self.create_publisher(Twist, "/cmd_vel", 10)
        self.create_timer(0.1, self.tick)

    def tick(self) -> None:
        t = self.get_clock().now().nanoseconds / 1e9
        msg = Twist()
        msg.linear.x, msg.angular.z = 0.3, 0.5 if t > 0.8 else -0.3
        self.pub.publish(msg)


async def _record_run(path: Path, duration_sec: float) -> None:
    from aiorobot.sim import Simulator

    async with Runtime(use_sim_time=True, handle_signals=False) as rt:
        rt.add_node(Recorder(path=str(path), exclude="^/(camera|scan|map)"))
        rt.add_node(Simulator(parameter_overrides={"world": "box", "real_time_factor": 0.0, "duration_sec": duration_sec,
                                                   "camera_rate": 0.0, "scan_rate": 0.0, "seed": 7}))
        rt.add_node(_Driver())
        rt.add_node(EkfNode(parameter_overrides=EKF))
        await rt.spin(duration_sec=60.0)


@pytest.fixture(scope="session")
def ekf_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """1.5 s of the simulator in lock-step (box world, seed 7), a driver on /cmd_vel, EkfNode, everything recorded."""
    path = tmp_path_factory.mktemp("ekf_run") / "run"
    asyncio.run(_record_run(path, 1.5))
    return path
