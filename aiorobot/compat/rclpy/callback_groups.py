"""``rclpy.callback_groups``: rclpy's protocol over aiorobot's groups.

The two stock groups are aiorobot's (a mutually exclusive group is an ``asyncio.Lock``
held across the whole callback) and also answer rclpy's ``can_execute`` /
``beginning_execution`` / ``ending_execution``. A program's own subclass of
:class:`CallbackGroup` (ros2/examples' token-bucket ``ThrottledCallbackGroup``) is asked
before each callback, as rclpy's executor asks: a callback it refuses waits until some
callback of the program has finished and asks again; a timer refused keeps one call
pending and skips the periods it missed, as an rcl timer that stays ready.
"""

from __future__ import annotations

import weakref
from typing import Any

from ..._core import _groups

__all__ = ["CallbackGroup", "MutuallyExclusiveCallbackGroup", "ReentrantCallbackGroup"]


class CallbackGroup(_groups.CallbackGroup):
    """rclpy's base class: subclasses decide with ``beginning_execution`` whether a callback may run."""

    def __init__(self) -> None:
        super().__init__()
        self.entities: set[weakref.ref[Any]] = set()

    def add_entity(self, entity: Any) -> None:
        self.entities.add(weakref.ref(entity))

    def has_entity(self, entity: Any) -> bool:
        return weakref.ref(entity) in self.entities

    def can_execute(self, entity: Any) -> bool:
        raise NotImplementedError()

    def beginning_execution(self, entity: Any) -> bool:
        raise NotImplementedError()

    def ending_execution(self, entity: Any) -> None:
        raise NotImplementedError()


class ReentrantCallbackGroup(_groups.ReentrantCallbackGroup, CallbackGroup):
    """Callbacks run in parallel (threads of a MultiThreadedExecutor), a callback with itself too."""

    def can_execute(self, entity: Any) -> bool:
        return True

    def beginning_execution(self, entity: Any) -> bool:
        return True

    def ending_execution(self, entity: Any) -> None:
        return None


class MutuallyExclusiveCallbackGroup(_groups.MutuallyExclusiveCallbackGroup, CallbackGroup):
    """One callback at a time; aiorobot holds the group's lock across the callback, awaits included."""

    def __init__(self) -> None:
        _groups.MutuallyExclusiveCallbackGroup.__init__(self)
        self.entities = set()

    def can_execute(self, entity: Any) -> bool:
        return not self.locked()

    def beginning_execution(self, entity: Any) -> bool:
        return not self.locked()

    def ending_execution(self, entity: Any) -> None:
        return None


def is_custom(group: Any) -> bool:
    """A program's own group: its ``beginning_execution`` decides (the stock ones are aiorobot's locks)."""
    return isinstance(group, CallbackGroup) and not isinstance(
        group, (ReentrantCallbackGroup, MutuallyExclusiveCallbackGroup)
    )
