"""Message filters: synchronise topics by their header stamps (ROS 2's ``message_filters``).

::

    left = Subscriber(node, Image, "/left/image_raw")
    right = Subscriber(node, Image, "/right/image_raw")
    sync = ApproximateTimeSynchronizer([left, right], queue_size=10, slop_sec=0.02)
    sync.register_callback(on_pair)          # on_pair(left_msg, right_msg), async or sync

The matching policies are plain classes (:class:`ExactTimePolicy`,
:class:`ApproximateTimePolicy`) usable without a runtime; :class:`Cache` keeps
a stamp-ordered history of an input.
"""

from __future__ import annotations

from ._filters import Cache, Connection, SimpleFilter, Subscriber
from ._policies import ApproximateTimePolicy, ExactTimePolicy
from ._sync import ApproximateTimeSynchronizer, TimeSynchronizer

__all__ = [
    "ApproximateTimePolicy",
    "ApproximateTimeSynchronizer",
    "Cache",
    "Connection",
    "ExactTimePolicy",
    "SimpleFilter",
    "Subscriber",
    "TimeSynchronizer",
]
