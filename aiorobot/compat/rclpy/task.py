"""``rclpy.task``: aiorobot's rclpy-style :class:`~aiorobot.Future` (thread-safe)."""

from ..._core._future import Future

__all__ = ["Future", "Task"]

Task = Future
