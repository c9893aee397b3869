"""aiorobot: an async-first asyncio robotics framework.

Nodes, topics, QoS, timers, callback groups, parameters and ROS 2 messages,
asyncio-native. See API.md for the public contract.
"""

from __future__ import annotations

from ._time import ClockType, Duration, Time

__all__ = ["ClockType", "Duration", "Time"]
