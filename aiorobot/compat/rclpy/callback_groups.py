"""``rclpy.callback_groups``: aiorobot's groups (a mutually exclusive group is held across the whole callback)."""

from ..._groups import CallbackGroup, MutuallyExclusiveCallbackGroup, ReentrantCallbackGroup

__all__ = ["CallbackGroup", "MutuallyExclusiveCallbackGroup", "ReentrantCallbackGroup"]
