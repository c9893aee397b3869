"""Message filters: synchronise topics by their header stamps (ROS 2's Python ``message_filters``).

::

    left = Subscriber(node, Image, "/left/image_raw")
    right = Subscriber(node, Image, "/right/image_raw")
    sync = ApproximateTimeSynchronizer([left, right], queue_size=10, slop=0.02)
    sync.registerCallback(on_pair)          # on_pair(left_msg, right_msg), async or sync

The synchronizers follow the Python ``message_filters`` package (a set is
delivered as soon as it exists; out-of-order input is fine); ``policy="cpp"``
selects the C++ policies (the optimal ``ApproximateTime``, ``ExactTime``).
The policies are plain classes usable without a runtime
(:class:`PythonExactTimePolicy`, :class:`PythonApproximateTimePolicy`,
:class:`ExactTimePolicy`, :class:`ApproximateTimePolicy`,
:class:`ApproximateEpsilonTimePolicy`, :class:`LatestTimePolicy`); :class:`Synchronizer`
runs any of them.
:class:`Cache` keeps a stamp-ordered history of an input.
"""

from __future__ import annotations

from ._filters import Cache, Connection, SimpleFilter, Subscriber
from ._policies import ApproximateTimePolicy, ExactTimePolicy
from ._py_policies import (
    ApproximateEpsilonTimePolicy,
    LatestTimePolicy,
    PythonApproximateTimePolicy,
    PythonExactTimePolicy,
)
from ._sync import ApproximateTimeSynchronizer, Synchronizer, TimeSynchronizer

__all__ = [
    "ApproximateEpsilonTimePolicy",
    "ApproximateTimePolicy",
    "ApproximateTimeSynchronizer",
    "Cache",
    "Connection",
    "ExactTimePolicy",
    "LatestTimePolicy",
    "PythonApproximateTimePolicy",
    "PythonExactTimePolicy",
    "SimpleFilter",
    "Subscriber",
    "Synchronizer",
    "TimeSynchronizer",
]
