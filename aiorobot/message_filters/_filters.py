"""Filter plumbing: callbacks, the subscription filter and the time-history cache."""

from __future__ import annotations

import asyncio
import bisect
import inspect
import logging
from collections.abc import Awaitable, Callable, Coroutine, Generator
from typing import TYPE_CHECKING, Any

from .._core._qos import QoSProfile
from .._core._time import Time

if TYPE_CHECKING:
    from .._core._groups import CallbackGroup
    from .._core._node import Node
    from .._core._pubsub import Subscription

__all__ = ["DONE", "Cache", "Connection", "SimpleFilter", "Subscriber", "stamp_ns_of"]

_log = logging.getLogger("aiorobot.message_filters")


def stamp_ns_of(msg: Any) -> int | None:
    """``msg.header.stamp`` in integer nanoseconds, or ``None`` for a message without a header stamp.

    The stamp may be a ``builtin_interfaces/msg/Time`` or an :class:`aiorobot.Time`.
    """
    header = getattr(msg, "header", None)
    stamp = getattr(header, "stamp", None)
    if stamp is None:
        return None
    if isinstance(stamp, Time):
        return stamp.nanoseconds
    return int(stamp.sec) * 1_000_000_000 + int(stamp.nanosec)


class _Done:
    """What a filter input returns when it finished synchronously: awaiting it does nothing."""

    __slots__ = ()

    def __await__(self) -> Generator[Any, None, None]:
        return iter(())

    def __repr__(self) -> str:
        return "<done>"


DONE: Any = _Done()


class Connection:
    """A registered callback; ``disconnect()`` unregisters it."""

    def __init__(self, owner: SimpleFilter, callback: Callable[..., Any], args: tuple[Any, ...] = ()) -> None:
        self._owner = owner
        self.callback = callback
        self.args = args

    def __repr__(self) -> str:
        return f"<Connection {self.callback!r} of {self._owner!r}>"

    @property
    def connected(self) -> bool:
        return self in self._owner._connections

    def disconnect(self) -> None:
        if self in self._owner._connections:
            self._owner._connections.remove(self)


class SimpleFilter:
    """A filter with outputs: ``registerCallback(cb, *args)``; ``cb(*messages, *args)`` may be ``async def`` or ``def``.

    Filters chain synchronously as in the Python ``message_filters`` package:
    ``signalMessage(*messages)`` calls every callback at once, so a chain of
    plain-function filters has finished when it returns. An ``async def``
    callback is awaited by :meth:`signal_message` (what the subscription does)
    and scheduled as a task by ``signalMessage``. ``node`` is the node whose
    clock and logger the filter uses (``None`` when it has none).
    """

    def __init__(self, node: Node | None = None) -> None:
        self.node = node
        self._connections: list[Connection] = []
        self._tasks: set[asyncio.Task[Any]] = set()

    def register_callback(self, callback: Callable[..., Any], *args: Any) -> Connection:
        """Call ``callback(*messages, *args)`` on every output of this filter, in registration order."""
        if not callable(callback):
            raise TypeError(f"registerCallback expects a callable, got {callback!r}")
        conn = Connection(self, callback, args)
        self._connections.append(conn)
        return conn

    registerCallback = register_callback

    def _signal(self, messages: tuple[Any, ...]) -> Any:
        """Call the callbacks in order; ``DONE`` when all finished, else an awaitable for the rest."""
        connections = list(self._connections)
        for k, conn in enumerate(connections):
            result = conn.callback(*messages, *conn.args)
            if result is not DONE and result is not None and inspect.isawaitable(result):
                return _Pending(result, connections[k + 1 :], messages)
        return DONE

    async def signal_message(self, *messages: Any) -> None:
        """Call every registered callback with ``messages``, awaiting ``async def`` ones in turn."""
        await self._signal(messages)

    def signalMessage(self, *messages: Any) -> None:  # noqa: N802 - the Python message_filters name
        """Call every registered callback with ``messages`` now (``async def`` ones are scheduled as tasks).

        An ``async def`` callback needs a running event loop; without one this raises ``RuntimeError``.
        """
        pending = self._signal(messages)
        if pending is DONE:
            return
        try:
            loop = asyncio.get_running_loop()
        except RuntimeError:
            pending.close()  # also closes the callback's own coroutine: no "never awaited" warning
            raise RuntimeError(
                f"{type(self).__name__}.signalMessage: a callback is async but no event loop is running; "
                "call it from a coroutine or use `await signal_message(...)`"
            ) from None
        task = loop.create_task(pending.run())
        self._tasks.add(task)
        task.add_done_callback(self._tasks.discard)

    def _logger_name(self) -> str:
        return self.node.get_fully_qualified_name() if self.node is not None else "<no node>"


class _Pending:
    """The callbacks still to run after the first ``async def`` one: await it, or ``close()`` it."""

    __slots__ = ("first", "messages", "rest")

    def __init__(self, first: Awaitable[Any], rest: list[Connection], messages: tuple[Any, ...]) -> None:
        self.first = first
        self.rest = rest
        self.messages = messages

    def __await__(self) -> Generator[Any, None, None]:
        return _finish(self.first, self.rest, self.messages).__await__()

    def run(self) -> Coroutine[Any, Any, None]:
        return _finish(self.first, self.rest, self.messages)

    def close(self) -> None:
        if inspect.iscoroutine(self.first):
            self.first.close()


async def _finish(first: Awaitable[Any], rest: list[Connection], messages: tuple[Any, ...]) -> None:
    await first
    for conn in rest:
        result = conn.callback(*messages, *conn.args)
        if result is not DONE and result is not None and inspect.isawaitable(result):
            await result


class Subscriber(SimpleFilter):
    """A node subscription as a filter input: every message it receives is passed on.

    Parameters
    ----------
    node
        The node that subscribes.
    msg_type, topic, qos
        As for ``Node.create_subscription``.
    callback_group
        The group the subscription's callback (and so the downstream filters' callbacks) runs in.
    """

    def __init__(
        self,
        node: Node,
        msg_type: type[Any],
        topic: str,
        qos_profile: QoSProfile | int = 10,
        *,
        callback_group: CallbackGroup | None = None,
    ) -> None:
        super().__init__(node)
        self.msg_type = msg_type
        self.topic = topic
        self.subscription: Subscription[Any] = node.create_subscription(
            msg_type, topic, self._on_message, qos_profile, callback_group=callback_group
        )
        self.sub = self.subscription  # the Python message_filters name

    def __repr__(self) -> str:
        return f"<Subscriber {self.topic_name} {self.subscription.type_name} of {self._logger_name()}>"

    @property
    def topic_name(self) -> str:
        """The resolved topic name."""
        return self.subscription.topic_name

    def getTopic(self) -> str:  # noqa: N802 - the Python message_filters name
        """The topic name as given."""
        return self.topic

    async def _on_message(self, msg: Any) -> None:
        await self._signal((msg,))

    def destroy(self) -> None:
        """Destroy the underlying subscription."""
        assert self.node is not None
        self.node.destroy_subscription(self.subscription)


class Cache(SimpleFilter):
    """The last ``cache_size`` messages of an input, ordered by stamp, queryable by time.

    Every message added is passed on to this filter's callbacks. With
    ``allow_headerless=True`` a message without ``header.stamp`` is stamped with
    the node's clock (or the system time) on arrival; otherwise it is dropped with
    a warning. The Python ``message_filters`` names work too (``getInterval``,
    ``getElemAfterTime``, ``getElemBeforeTime``, ``getLastestTime``,
    ``getOldestTime``, ``getLast``).

    rclpy difference: messages are kept sorted by stamp and a full cache drops the
    oldest *stamp* (the Python package keeps arrival order and drops the first to
    arrive), so out-of-order input is answered correctly, as by the C++ ``Cache``.
    """

    def __init__(self, input_filter: SimpleFilter | None = None, cache_size: int = 1, allow_headerless: bool = False) -> None:
        super().__init__(input_filter.node if input_filter is not None else None)
        if isinstance(cache_size, bool) or not isinstance(cache_size, int) or cache_size < 1:
            raise ValueError(f"cache_size: expected an int >= 1, got {cache_size!r}")
        self.cache_size = cache_size
        self.allow_headerless = allow_headerless
        self._stamps: list[int] = []
        self._msgs: list[Any] = []
        self._warned_headerless = False
        self.incoming: Connection | None = None
        if input_filter is not None:
            self.connect_input(input_filter)

    def __repr__(self) -> str:
        return f"<Cache {len(self._msgs)}/{self.cache_size} messages>"

    def __len__(self) -> int:
        return len(self._msgs)

    def connect_input(self, input_filter: SimpleFilter) -> None:
        if self.incoming is not None:
            self.incoming.disconnect()
        if self.node is None:
            self.node = input_filter.node
        self.incoming = input_filter.register_callback(self.add)

    connectInput = connect_input

    def add(self, msg: Any) -> Any:
        """Insert ``msg`` by its stamp (dropping the oldest beyond ``cache_size``) and pass it on.

        Runs the callbacks at once as the Python ``Cache.add`` does; returns an
        awaitable that finishes any ``async def`` callbacks (awaiting it is optional
        when they are all plain functions).
        """
        if not self.add_nowait(msg):
            return DONE
        return self._signal((msg,))

    def add_nowait(self, msg: Any) -> bool:
        """Insert ``msg`` without calling the callbacks; ``False`` when it was dropped for lack of a stamp."""
        stamp = stamp_ns_of(msg)
        if stamp is None:
            if not self.allow_headerless:
                if not self._warned_headerless:
                    _log.warning(
                        "Cache of %s: %s has no header.stamp; dropped. Pass allow_headerless=True to stamp "
                        "such messages on arrival",
                        self._logger_name(),
                        type(msg).__name__,
                    )
                    self._warned_headerless = True
                return False
            stamp = _now_ns(self)
        i = bisect.bisect_right(self._stamps, stamp)
        self._stamps.insert(i, stamp)
        self._msgs.insert(i, msg)
        if len(self._msgs) > self.cache_size:
            del self._stamps[0]
            del self._msgs[0]
        return True

    def get_interval(self, start: Time, end: Time) -> list[Any]:
        """Messages stamped in ``[start, end]``, oldest first."""
        lo = bisect.bisect_left(self._stamps, start.nanoseconds)
        hi = bisect.bisect_right(self._stamps, end.nanoseconds)
        return self._msgs[lo:hi]

    def get_surrounding_interval(self, start: Time, end: Time) -> list[Any]:
        """As :meth:`get_interval`, plus the newest message before ``start`` and the oldest after ``end``."""
        lo = max(bisect.bisect_right(self._stamps, start.nanoseconds) - 1, 0)
        hi = min(bisect.bisect_left(self._stamps, end.nanoseconds) + 1, len(self._msgs))
        return self._msgs[lo:hi]

    def get_elem_after_time(self, time: Time) -> Any | None:
        """The oldest message stamped at or after ``time``."""
        i = bisect.bisect_left(self._stamps, time.nanoseconds)
        return self._msgs[i] if i < len(self._msgs) else None

    def get_elem_before_time(self, time: Time) -> Any | None:
        """The newest message stamped at or before ``time``."""
        i = bisect.bisect_right(self._stamps, time.nanoseconds)
        return self._msgs[i - 1] if i > 0 else None

    def get_latest_time(self) -> Time | None:
        return Time(nanoseconds=self._stamps[-1]) if self._stamps else None

    def get_oldest_time(self) -> Time | None:
        return Time(nanoseconds=self._stamps[0]) if self._stamps else None

    def get_last(self) -> Any | None:
        """The newest message, or ``None`` when empty."""
        return self._msgs[-1] if self._msgs else None

    # The Python message_filters names (``getLastestTime`` keeps upstream's spelling).
    getInterval = get_interval
    getSurroundingInterval = get_surrounding_interval
    getElemAfterTime = get_elem_after_time
    getElemBeforeTime = get_elem_before_time
    getLastestTime = get_latest_time
    getLatestTime = get_latest_time
    getOldestTime = get_oldest_time
    getLast = get_last


def _now_ns(f: SimpleFilter) -> int:
    if f.node is not None:
        return f.node.now().nanoseconds
    import time

    return time.time_ns()
