"""Managed (lifecycle) nodes, as ROS 2's: states, transitions with hooks, lifecycle publishers, services.

::

    class Camera(LifecycleNode):
        def __init__(self, **kw):
            super().__init__("camera", **kw)
            self.pub = self.create_lifecycle_publisher(Image, "image", 5)

        async def on_configure(self, state):
            self.device = open_device()            # raise, or return FAILURE, to refuse
            return TransitionCallbackReturn.SUCCESS

    await camera.trigger_configure()               # -> LifecycleState.INACTIVE
    await camera.trigger_transition("activate")    # -> LifecycleState.ACTIVE
"""

from __future__ import annotations

from ._node import LifecycleNode
from ._publisher import LifecyclePublisher
from ._state_machine import (
    TRANSITIONS,
    InvalidTransitionError,
    LifecycleState,
    LifecycleStateMachine,
    LifecycleTransition,
    TransitionCallbackReturn,
    TransitionDescription,
)

__all__ = [
    "TRANSITIONS",
    "InvalidTransitionError",
    "LifecycleNode",
    "LifecyclePublisher",
    "LifecycleState",
    "LifecycleStateMachine",
    "LifecycleTransition",
    "TransitionCallbackReturn",
    "TransitionDescription",
]
