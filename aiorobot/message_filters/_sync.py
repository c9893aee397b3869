"""Time synchronizers: one callback with a matched message per input."""

from __future__ import annotations

import functools
import logging
import threading
from collections.abc import Sequence
from typing import Any

from ._filters import DONE, SimpleFilter, _now_ns, stamp_ns_of
from ._policies import ApproximateTimePolicy, ExactTimePolicy
from ._py_policies import PythonApproximateTimePolicy, PythonExactTimePolicy

__all__ = ["ApproximateTimeSynchronizer", "Synchronizer", "TimeSynchronizer"]

_log = logging.getLogger("aiorobot.message_filters")


def _check_slop(slop: Any) -> float:
    if isinstance(slop, bool) or not isinstance(slop, (int, float)) or not slop >= 0:
        raise ValueError(f"slop: expected a number of seconds >= 0, got {slop!r}")
    return float(slop)


def _check_policy(owner: str, policy: str) -> None:
    if policy not in _POLICIES:
        raise ValueError(
            f"{owner} policy: expected 'python' (the Python message_filters) or 'cpp' (the C++ policy), "
            f"got {policy!r}"
        )


_POLICIES = ("python", "cpp")


class Synchronizer(SimpleFilter):
    """Feeds each input's messages to a policy and signals the sets it outputs (C++ ``Synchronizer<Policy>``).

    ``policy`` is any object with ``add(index, stamp_ns, message) -> list of sets``:
    :class:`PythonExactTimePolicy`, :class:`PythonApproximateTimePolicy`,
    :class:`ExactTimePolicy`, :class:`ApproximateTimePolicy`,
    :class:`ApproximateEpsilonTimePolicy`, :class:`LatestTimePolicy` or your own.
    A policy with ``needs_stamps = False`` takes messages without headers; one
    with ``now_ns = None`` gets the node clock. :class:`TimeSynchronizer`
    and :class:`ApproximateTimeSynchronizer` are this with the policy chosen for you.
    """

    def __init__(self, inputs: Sequence[SimpleFilter], policy: Any, *, allow_headerless: bool = False) -> None:
        inputs = list(inputs)
        for f in inputs:
            if not isinstance(f, SimpleFilter):
                raise TypeError(
                    f"{type(self).__name__} inputs must be message filters (e.g. message_filters.Subscriber), got {f!r}"
                )
        n = getattr(policy, "n_inputs", len(inputs))
        if n != len(inputs):
            raise ValueError(f"{type(self).__name__}: the policy expects {n} inputs, got {len(inputs)}")
        node = next((f.node for f in inputs if f.node is not None), None)
        super().__init__(node)
        self.inputs = inputs
        self.policy = policy
        self._needs_stamps = getattr(policy, "needs_stamps", True)
        if hasattr(policy, "now_ns") and policy.now_ns is None:
            policy.now_ns = functools.partial(_now_ns, self)  # arrival times on the node clock
        self.allow_headerless = allow_headerless
        self._lock = threading.Lock()  # inputs may live on different loops
        self._warned_headerless = False
        self.input_connections = [f.register_callback(functools.partial(self.add, i)) for i, f in enumerate(inputs)]

    def __repr__(self) -> str:
        return f"<{type(self).__name__} inputs={len(self.inputs)} {self.policy!r}>"

    def add(self, index: int, msg: Any) -> Any:
        """Add ``msg`` on input ``index`` (what the inputs call) and signal every completed set at once.

        Returns an awaitable that finishes the ``async def`` callbacks, if any.
        """
        stamp = stamp_ns_of(msg) if self._needs_stamps else 0
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
                return DONE
            stamp = _now_ns(self)
        with self._lock:
            sets = self.policy.add(index, stamp, msg)
        for k, matched in enumerate(sets):
            pending = self._signal(matched)
            if pending is not DONE:
                rest = sets[k + 1 :]
                return self._signal_rest(pending, rest) if rest else pending
        return DONE

    async def _signal_rest(self, pending: Any, sets: list[tuple[Any, ...]]) -> None:
        await pending
        for matched in sets:
            await self._signal(matched)

    def disconnect_inputs(self) -> None:
        for conn in self.input_connections:
            conn.disconnect()


class TimeSynchronizer(Synchronizer):
    """Calls back with one message per input when their ``header.stamp`` are exactly equal.

    The Python ``message_filters.TimeSynchronizer``: each input keeps its last
    ``queue_size`` stamps, and a set is delivered as soon as a stamp is present
    on every input, in any arrival order (:class:`PythonExactTimePolicy`).
    ``policy="cpp"`` selects the C++ ``ExactTime`` policy instead
    (:class:`ExactTimePolicy`: ``queue_size`` counts incomplete sets, and an
    output set drops every older incomplete one).

    Parameters
    ----------
    fs
        Two or more filters (usually :class:`Subscriber`); the callback receives
        their messages in this order.
    queue_size
        Stamps kept per input (``policy="cpp"``: incomplete sets kept).
    policy
        ``"python"`` (default) or ``"cpp"``.
    """

    def __init__(self, fs: Sequence[SimpleFilter], queue_size: int, *, policy: str = "python") -> None:
        _check_policy(type(self).__name__, policy)
        n = len(list(fs))
        chosen: Any = PythonExactTimePolicy(n, queue_size) if policy == "python" else ExactTimePolicy(n, queue_size)
        super().__init__(fs, chosen, allow_headerless=False)
        self.queue_size = queue_size


class ApproximateTimeSynchronizer(Synchronizer):
    """Calls back with a set of messages, one per input, whose stamps lie within ``slop`` seconds.

    The Python ``message_filters.ApproximateTimeSynchronizer`` (the default,
    :class:`PythonApproximateTimePolicy`): each input keeps its last
    ``queue_size`` stamps, and as soon as a new message completes a set whose
    span is within ``slop`` it is delivered, closest stamps first; messages may
    arrive out of order. ``policy="cpp"`` selects the C++ optimal
    ``ApproximateTime`` policy (:class:`ApproximateTimePolicy`): it delivers the
    set with the smallest span, which means the newest set waits for one more
    message, and it needs inputs in stamp order.

    rclpy difference: a set whose span equals ``slop`` exactly is delivered
    (upstream's final check is strict, so ``slop=0`` never matches anything); the
    C++ optimal policy is available with ``policy="cpp"``.

    Parameters
    ----------
    fs
        Two or more filters; the callback receives their messages in this order.
    queue_size
        Messages kept per input.
    slop
        The widest span (newest stamp minus oldest) a set may have, in seconds.
    allow_headerless
        Stamp messages without ``header.stamp`` with the node clock on arrival.
    policy
        ``"python"`` (default) or ``"cpp"``.
    age_penalty
        ``policy="cpp"`` only: how much better a newer candidate set must be to replace an older one.
    """

    def __init__(
        self,
        fs: Sequence[SimpleFilter],
        queue_size: int,
        slop: float,
        allow_headerless: bool = False,
        *,
        policy: str = "python",
        age_penalty: float = 0.1,
    ) -> None:
        slop = _check_slop(slop)
        _check_policy(type(self).__name__, policy)
        n = len(list(fs))
        slop_ns = round(slop * 1e9)
        chosen: Any
        if policy == "python":
            chosen = PythonApproximateTimePolicy(n, queue_size, slop_ns)
        else:
            chosen = ApproximateTimePolicy(n, queue_size, max_interval_ns=slop_ns, age_penalty=age_penalty)
        super().__init__(fs, chosen, allow_headerless=allow_headerless)
        self.queue_size = queue_size
        self.slop = slop

    def set_inter_message_lower_bound(self, index: int, lower_bound_sec: float) -> None:
        """``policy="cpp"``: declare that input ``index`` never sends two messages closer than ``lower_bound_sec``.

        Lets sets be output without waiting for a newer message on that input.
        """
        if not isinstance(self.policy, ApproximateTimePolicy):
            raise TypeError(
                "set_inter_message_lower_bound needs the C++ policy: ApproximateTimeSynchronizer(..., policy='cpp')"
            )
        self.policy.set_inter_message_lower_bound(index, round(lower_bound_sec * 1e9))
