"""Time synchronizers: one callback with a matched message per input."""

from __future__ import annotations

import functools
import logging
import threading
from collections.abc import Sequence
from typing import Any

from ._filters import SimpleFilter, _now_ns, stamp_ns_of
from ._policies import ApproximateTimePolicy, ExactTimePolicy

__all__ = ["ApproximateTimeSynchronizer", "TimeSynchronizer"]

_log = logging.getLogger("aiorobot.message_filters")


class _Synchronizer(SimpleFilter):
    """Feeds each input's messages to a policy and signals the sets it outputs."""

    def __init__(self, inputs: Sequence[SimpleFilter], policy: Any, *, allow_headerless: bool) -> None:
        inputs = list(inputs)
        for f in inputs:
            if not isinstance(f, SimpleFilter):
                raise TypeError(
                    f"{type(self).__name__} inputs must be message filters (e.g. message_filters.Subscriber), got {f!r}"
                )
        node = next((f.node for f in inputs if f.node is not None), None)
        super().__init__(node)
        self.inputs = inputs
        self.policy = policy
        self.allow_headerless = allow_headerless
        self._lock = threading.Lock()  # inputs may live on different loops
        self._warned_headerless = False
        self.input_connections = [f.register_callback(functools.partial(self.add, i)) for i, f in enumerate(inputs)]

    def __repr__(self) -> str:
        return f"<{type(self).__name__} inputs={len(self.inputs)} {self.policy!r}>"

    async def add(self, index: int, msg: Any) -> None:
        """Add ``msg`` on input ``index`` (what the inputs call); signals every completed set."""
        stamp = stamp_ns_of(msg)
        if stamp is None:
            if not self.allow_headerless:
                if not self._warned_headerless:
                    _log.warning(
                        "%s of %s: input %d sent %s, which has no header.stamp; dropped. Use message types "
                        "with a header, or ApproximateTimeSynchronizer(..., allow_headerless=True) to stamp "
                        "them on arrival",
                        type(self).__name__,
                        self._logger_name(),
                        index,
                        type(msg).__name__,
                    )
                    self._warned_headerless = True
                return
            stamp = _now_ns(self)
        with self._lock:
            sets = self.policy.add(index, stamp, msg)
        for matched in sets:
            await self.signal_message(*matched)

    def disconnect_inputs(self) -> None:
        for conn in self.input_connections:
            conn.disconnect()


class TimeSynchronizer(_Synchronizer):
    """Calls back with one message per input when their ``header.stamp`` are exactly equal.

    Parameters
    ----------
    inputs
        Two or more filters (usually :class:`Subscriber`); the callback receives
        their messages in this order.
    queue_size
        How many incomplete sets to keep waiting (older ones are dropped; an
        output set also drops every older incomplete one, as ROS 2's ``ExactTime``).
    """

    def __init__(self, inputs: Sequence[SimpleFilter], queue_size: int) -> None:
        super().__init__(inputs, ExactTimePolicy(len(inputs), queue_size), allow_headerless=False)
        self.queue_size = queue_size


class ApproximateTimeSynchronizer(_Synchronizer):
    """Calls back with the best-matching set of messages whose stamps lie within ``slop_sec``.

    Implements ROS 2's ``ApproximateTime`` policy (see :class:`ApproximateTimePolicy`):
    each message is used at most once, a set is output once no later message
    could make a tighter set (so the newest set waits for one more message),
    messages older than an output set are dropped, and an input holding more than
    ``queue_size`` messages drops its oldest. No set spans more than ``slop_sec``.

    Parameters
    ----------
    inputs
        Two or more filters; the callback receives their messages in this order.
    queue_size
        Messages kept per input.
    slop_sec
        The widest span (newest stamp minus oldest) a set may have, in seconds.
    allow_headerless
        Stamp messages without ``header.stamp`` with the node clock on arrival.
    age_penalty
        How much better a newer candidate set must be to replace an older one.
    """

    def __init__(
        self,
        inputs: Sequence[SimpleFilter],
        queue_size: int,
        slop_sec: float,
        allow_headerless: bool = False,
        *,
        age_penalty: float = 0.1,
    ) -> None:
        if isinstance(slop_sec, bool) or not isinstance(slop_sec, (int, float)) or not slop_sec >= 0:
            raise ValueError(f"slop_sec: expected a number of seconds >= 0, got {slop_sec!r}")
        policy: ApproximateTimePolicy[Any] = ApproximateTimePolicy(
            len(inputs), queue_size, max_interval_ns=round(slop_sec * 1e9), age_penalty=age_penalty
        )
        super().__init__(inputs, policy, allow_headerless=allow_headerless)
        self.queue_size = queue_size
        self.slop_sec = float(slop_sec)

    def set_inter_message_lower_bound(self, index: int, lower_bound_sec: float) -> None:
        """Declare that input ``index`` never sends two messages closer than ``lower_bound_sec``.

        Lets sets be output without waiting for a newer message on that input.
        """
        self.policy.set_inter_message_lower_bound(index, round(lower_bound_sec * 1e9))
