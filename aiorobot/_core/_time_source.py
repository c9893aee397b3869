"""A node's ``use_sim_time`` parameter, as rclpy's ``TimeSource``.

Every node declares ``use_sim_time``. Left alone, it follows the runtime (and reads
``Runtime(use_sim_time=...)``); a node whose parameter says otherwise - by override,
parameter file, ``-p use_sim_time:=true`` or a set at run time - gets a clock of its
own, fed from ``/clock`` by a subscription of its own when it is on, and its timers
restart their period on the new time base.

In a wall-time runtime every node has its own ROS clock, so jump callbacks registered on
``node.get_clock()`` see ROS time switch on and off. In a sim-time runtime nodes share the
runtime's clock; switching one off moves it to a clock of its own, and jump callbacks
registered on ``node.get_clock()`` before that stay on the runtime's clock.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from ._clock import Clock
from ._parameter_types import Parameter
from ._time import ClockType

if TYPE_CHECKING:
    from ._node import Node
    from ._pubsub import Subscription
    from ._runtime import Runtime

__all__ = ["TimeSource"]

PARAMETER = "use_sim_time"


class TimeSource:
    """Keeps ``node``'s clock in step with its ``use_sim_time`` parameter."""


    def __init__(self, node: Node) -> None:
        self.node = node
        store = node._parameters
        self.explicit = PARAMETER in store.overrides
        if not node.has_parameter(PARAMETER):
            node.declare_parameter(PARAMETER, False, description="follow /clock instead of the system clock")
        self._own: Clock | None = None
        self._clock_sub: Subscription[Any] | None = None
        node.add_post_set_parameters_callback(self._on_set)

    def __repr__(self) -> str:
        return f"<TimeSource of {self.node.get_fully_qualified_name()} own_clock={self._own is not None}>"

    @property
    def wanted(self) -> bool:
        return bool(self.node._parameters._values[PARAMETER].value)

    def clock_for(self, runtime: Runtime) -> Clock:
        """The clock ``node`` uses in ``runtime`` (called when it is added).

        In a wall-time runtime every node has a ROS clock of its own (ROS time off until its
        parameter turns it on), so jump callbacks on ``node.get_clock()`` see the switch; in
        a sim-time runtime a node shares the runtime's clock until its parameter says otherwise.
        """
        if not self.explicit:  # follow the runtime, and say so in the parameter
            store = self.node._parameters
            store._values[PARAMETER] = Parameter(PARAMETER, value=bool(runtime.use_sim_time))
        if runtime.use_sim_time and self.wanted and self._own is None:
            return runtime.clock
        return self._own_clock(runtime)

    def _own_clock(self, runtime: Runtime) -> Clock:
        if self._own is None:
            own = Clock(ClockType.ROS_TIME)
            shared = runtime.clock
            if shared.use_sim_time:
                own.set_ros_time_override(shared.now())
            self._own = own
        self._own._set_ros_time_is_active(self.wanted)
        if self.wanted and self._clock_sub is None:
            from ._qos import QoSProfile
            from ..msgs.rosgraph_msgs import Clock as ClockMsg

            self._clock_sub = self.node.create_subscription(ClockMsg, "/clock", self._on_clock, QoSProfile(depth=1))
        return self._own

    def _on_clock(self, msg: Any) -> None:
        if self._own is not None and self._own.use_sim_time:
            self._own.set_sim_time(int(msg.clock.sec) * 1_000_000_000 + int(msg.clock.nanosec))

    def _on_set(self, params: list[Parameter]) -> None:
        if not any(p.name == PARAMETER for p in params):
            return
        self.explicit = True
        node = self.node
        runtime = node._runtime
        if runtime is None:
            return  # decided when the node is added
        clock = runtime.clock if (runtime.use_sim_time and self.wanted and self._own is None) else self._own_clock(runtime)
        if clock is not node._clock:
            node._clock = clock
            node._logger._bind_clock(clock)
        if node._started:
            for timer in node._timers:
                if not timer._cancelled:
                    timer.reset()
