"""``nav2_simple_commander`` for rclpy programs on aiorobot: :mod:`.robot_navigator`'s BasicNavigator."""

from __future__ import annotations

from .robot_navigator import BasicNavigator, RunningTask, TaskResult

__all__ = ["BasicNavigator", "RunningTask", "TaskResult"]
