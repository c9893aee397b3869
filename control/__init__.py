"""aiorobot.control: kinematics, controllers, the serial motor protocol and bridge, a simulated firmware.

Pure cores (numpy in, numpy out, no runtime): :class:`DiffDrive`, :class:`Mecanum`,
:func:`saturate_wheel_speeds`, :func:`integrate_twist`, :class:`WheelOdometry`,
:class:`PID`, :class:`VelocitySmoother`, :class:`GoToGoal`, :class:`PurePursuit`.
"""

from __future__ import annotations

from ._go_to_goal import DriveCommand, GoToGoal
from ._kinematics import DiffDrive, Kinematics, Mecanum, saturate_wheel_speeds
from ._odometry import WheelOdometry, integrate_twist, tick_delta, wrap_angle
from ._pid import PID
from ._pure_pursuit import PurePursuit, check_path
from ._smoother import VelocitySmoother

__all__ = [
    "DiffDrive",
    "DriveCommand",
    "GoToGoal",
    "Kinematics",
    "Mecanum",
    "PID",
    "PurePursuit",
    "VelocitySmoother",
    "WheelOdometry",
    "check_path",
    "integrate_twist",
    "saturate_wheel_speeds",
    "tick_delta",
    "wrap_angle",
]
