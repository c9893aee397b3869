"""rclpy's ``Node`` on aiorobot's: rclpy's signatures, blocking calls, callbacks through the executor."""

from __future__ import annotations

import asyncio
import copy
import functools
import inspect
import threading
import time
from collections.abc import Callable, Sequence
from typing import Any

from .._core import _actions, _services
from .._core._node import Node as _AioNode
from .._core._event_handler import _EventCallbacks
from .._core._qos import QoSProfile, to_qos_profile
from .._core._timer import Rate as _AioRate
from ..lowlevel import add_client, node_loop
from ._context import Context, default_context
from ._dispatch import gate_callback, wrap_callback
from .rclpy.callback_groups import CallbackGroup, is_custom
from ._missing import not_provided

__all__ = ["Client", "NodeMixin", "Rate", "make_node_class"]

#: Node methods of rclpy that aiorobot lacks: using one raises NotProvidedError.
MISSING_NODE_METHODS = frozenset(
    {
        "add_waitable",
        "remove_waitable",
        "waitables",
        "handle",
        "get_clients_info_by_service",
        "get_servers_info_by_service",
    }
)


class Client(_services.Client):
    """rclpy's ``Client``: ``wait_for_service`` and ``call`` block; ``call_async`` waits for the server."""

    _context: Context

    def wait_for_service(self, timeout_sec: float | None = None) -> bool:  # type: ignore[override]
        ctx = self._context
        if ctx.in_callback() and ctx.loop is not None and ctx.loop.is_running():
            deadline = None if timeout_sec is None else time.monotonic() + timeout_sec
            while not self.service_is_ready():
                if deadline is not None and time.monotonic() >= deadline:
                    return False
                time.sleep(0.01)
            return True
        return ctx.run_sync(_services.Client.wait_for_service(self, timeout_sec), "Client.wait_for_service")

    async def _call_when_ready(self, request: Any) -> Any:
        await _services.Client.wait_for_service(self, None)
        return await _services.Client.call(self, request)

    def call_async(self, request: Any) -> Any:
        from .._core._future import future_of

        self._check_request(request)
        ctx = self._context
        fut = future_of(self._call_when_ready(request), None if _services._in_loop() else node_loop(self.node))
        fut.add_done_callback(lambda _f: ctx.callback_finished())
        return fut

    def call(self, request: Any, timeout_sec: float | None = None) -> Any:  # type: ignore[override]
        """Send ``request`` and block until the response (``TimeoutError`` after ``timeout_sec``)."""
        self._check_request(request)
        return self._context.run_sync(_services.Client.call(self, request, timeout_sec), "Client.call")


class Rate:
    """rclpy's ``Rate``: ``sleep()`` blocks the calling thread until the next period (absolute grid).

    As rclpy's, it runs on the node's clock unless given another, so under ``use_sim_time`` it
    follows ``/clock`` (sim time moves only while some thread spins, as with rclpy, whose Rate
    is a timer); ``Node.destroy_rate`` wakes a thread sleeping on it (its ``sleep()`` returns),
    a later ``sleep()`` raises ``RuntimeError``, and shutting the context down wakes a sleeper
    with ``ROSInterruptException``.
    """

    def __init__(self, frequency: float, context: Context | None = None, clock: Any = None) -> None:
        if isinstance(frequency, bool) or not isinstance(frequency, (int, float)) or frequency <= 0:
            raise ValueError(f"Rate: expected a frequency in Hz > 0, found {frequency!r}")
        self._period = 1.0 / frequency
        self._period_ns = round(1e9 / frequency)
        self._next = time.monotonic() + self._period
        self._clock = clock
        self._context = context
        self._next_sim: int | None = None  # the sim-time grid, started at the first sleep on sim time
        self._destroyed = False
        self._is_shutdown = False
        self._event = threading.Event()
        self._sleepers: set[threading.Event] = set()
        if context is not None:
            context.on_shutdown(self._on_shutdown)

    def _on_shutdown(self) -> None:
        self._is_shutdown = True
        self.destroy()

    def sleep(self) -> None:
        """Block the calling thread until the next period on the rate's clock.

        rclpy difference: on wall time it needs no thread spinning (rclpy's Rate is a timer,
        which fires only while an executor spins); on sim time, called in a callback of a spin
        in the same thread, it raises ``RuntimeError`` where rclpy's blocks that thread for ever
        (the ``/clock`` that would wake it cannot be taken while it sleeps).
        """
        from .rclpy.exceptions import ROSInterruptException

        if self._is_shutdown:
            raise ROSInterruptException()
        if self._destroyed:
            raise RuntimeError("Rate cannot sleep because it has been destroyed")
        clock = self._clock
        if clock is not None and clock.use_sim_time:
            self._sleep_sim(clock)
        else:
            now = time.monotonic()
            if now >= self._next + self._period:
                self._next = now + self._period
            delay = self._next - now
            self._next += self._period
            if delay > 0:
                self._event.wait(delay)
        if self._is_shutdown:
            raise ROSInterruptException()

    def _sleep_sim(self, clock: Any) -> None:
        """Until sim time reaches the next period: a waiter on the clock, registered on the loop."""
        now = clock.now_ns()
        if self._next_sim is None or now >= self._next_sim + self._period_ns:
            self._next_sim = now + self._period_ns  # first sleep, or fell behind: restart the grid
        deadline = self._next_sim
        self._next_sim += self._period_ns
        if now >= deadline:
            return
        loop = self._context.loop if self._context is not None else None
        if loop is None or loop.is_closed():
            return
        if asyncio._get_running_loop() is loop:  # a callback of a spin on this thread
            raise RuntimeError(
                "Rate.sleep on sim time in a callback of a single-threaded spin would never wake: "
                "the loop that moves sim time (/clock) is blocked in it; sleep in another thread"
            )
        woken = threading.Event()
        waiting: list[asyncio.Future[None]] = []

        def register() -> None:
            fut = loop.create_future()
            fut.add_done_callback(lambda f: (f.cancelled() or f.exception(), woken.set()))
            waiting.append(fut)
            try:
                clock.add_waiter(deadline, fut)
            except RuntimeError:  # ROS time was switched off meanwhile
                woken.set()

        self._sleepers.add(woken)
        try:
            if self._destroyed:
                return
            loop.call_soon_threadsafe(register)
            woken.wait()
        finally:
            self._sleepers.discard(woken)
            if not loop.is_closed():
                loop.call_soon_threadsafe(lambda: [f.cancel() for f in waiting])
        if waiting and waiting[0].done() and not waiting[0].cancelled() and waiting[0].exception() is not None:
            self._next_sim = None  # sim time jumped back (ClockJump): the grid restarts on the new time

    def destroy(self) -> None:
        self._destroyed = True
        self._event.set()
        for woken in list(self._sleepers):
            woken.set()


class NodeMixin:
    """What turns an aiorobot node class into rclpy's: put it first among the bases."""

    _context: Context

    def _compat_init(
        self,
        node_name: str,
        context: Context | None,
        cli_args: Sequence[str] | None,
        namespace: str | None,
        use_global_arguments: bool,
        kwargs: dict[str, Any],
        base_init: Callable[..., None],
    ) -> None:
        ctx = context or default_context()
        ctx.require_ok(f"Node({node_name!r})")
        args = list(ctx.argv if use_global_arguments else []) + list(cli_args or [])
        self._context = ctx
        self._executor_ref = None
        base_init(self, node_name, namespace=namespace or "", cli_args=args, **kwargs)
        assert ctx.runtime is not None
        ctx.runtime.add_node(self)  # type: ignore[arg-type]

    @property
    def context(self) -> Context:
        return self._context

    def _wrap(self, callback: Any, group: Any = None, *, coalesce: bool = False) -> tuple[Any, list[Any]]:
        """The callback as the executor runs it, and a one-slot list to put its entity in."""
        slot: list[Any] = []
        if getattr(self, "_compat_raw", 0):
            return callback, slot  # aiorobot's own entities (action internals, parameter services)
        wrapped = wrap_callback(self._context, callback, (self, slot))
        if is_custom(group):
            wrapped = gate_callback(self._context, group, wrapped, lambda: slot[0], coalesce=coalesce)
        return wrapped, slot

    @staticmethod
    def _entity(entity: Any, slot: list[Any], group: Any) -> Any:
        slot.append(entity)
        if isinstance(group, CallbackGroup):
            group.add_entity(entity)
        return entity

    def _wrap_events(self, event_callbacks: Any, group: Any) -> tuple[Any, dict[str, list[Any]]]:
        """A copy of ``event_callbacks`` whose callbacks run as the program's others do, and their slots."""
        if not isinstance(event_callbacks, _EventCallbacks):
            return event_callbacks, {}  # None, or a wrong type aiorobot's entity names
        from .rclpy.event_handler import rclpy_status

        events = copy.copy(event_callbacks)
        slots: dict[str, list[Any]] = {}
        for name in events._events:
            callback = getattr(events, name, None)
            if callback is None or not callable(callback):
                continue  # not callable: aiorobot's entity raises TypeError naming it
            if inspect.iscoroutinefunction(callback):
                async def adapted(status: Any, _cb: Any = callback) -> Any:
                    return await _cb(rclpy_status(status))
            else:
                def adapted(status: Any, _cb: Any = callback) -> Any:  # type: ignore[misc]
                    return _cb(rclpy_status(status))
            functools.update_wrapper(adapted, callback)
            wrapped, slots[name] = self._wrap(adapted, group)
            setattr(events, name, wrapped)
        return events, slots

    def _add_event_entities(self, entity: Any, slots: dict[str, list[Any]], group: Any) -> None:
        for name, slot in slots.items():
            self._entity(entity._events[name], slot, group)  # rclpy's entity: the EventHandler

    def _qos_for(self, kind: str, topic: str, qos_profile: Any, options: Any) -> QoSProfile:
        from .rclpy.qos import frozen
        from .rclpy.qos_overriding_options import declare_qos_parameters

        qos = to_qos_profile(frozen(qos_profile))
        if options is None:
            return qos
        return declare_qos_parameters(kind, self, self.resolve_topic_name(topic), qos, options)  # type: ignore[attr-defined]

    def create_publisher(  # type: ignore[override]
        self, msg_type: Any, topic: str, qos_profile: QoSProfile | int, *, callback_group: Any = None,
        event_callbacks: Any = None, qos_overriding_options: Any = None, publisher_class: Any = None,
    ) -> Any:
        qos = self._qos_for("publisher", topic, qos_profile, qos_overriding_options)
        events, slots = self._wrap_events(event_callbacks, callback_group)
        pub = super().create_publisher(  # type: ignore[misc]
            msg_type, topic, qos, callback_group=callback_group, event_callbacks=events
        )
        self._add_event_entities(pub, slots, callback_group)
        return pub

    def create_subscription(  # type: ignore[override]
        self, msg_type: Any, topic: str, callback: Callable[[Any], Any], qos_profile: QoSProfile | int, *,
        callback_group: Any = None, event_callbacks: Any = None, qos_overriding_options: Any = None, raw: bool = False,
    ) -> Any:
        qos = self._qos_for("subscription", topic, qos_profile, qos_overriding_options)
        wrapped, slot = self._wrap(callback, callback_group)
        events, slots = self._wrap_events(event_callbacks, callback_group)
        sub = super().create_subscription(  # type: ignore[misc]
            msg_type, topic, wrapped, qos, callback_group=callback_group, event_callbacks=events, raw=raw
        )
        self._add_event_entities(sub, slots, callback_group)
        return self._entity(sub, slot, callback_group)

    def create_timer(  # type: ignore[override]
        self, timer_period_sec: float, callback: Callable[..., Any], callback_group: Any = None,
        clock: Any = None, autostart: bool = True,
    ) -> Any:
        wrapped, slot = self._wrap(callback, callback_group, coalesce=True)
        if timer_period_sec == 0 and not isinstance(timer_period_sec, bool):
            # rcl takes a zero period (a timer ready on every pass of the executor, as
            # deadline.py's `--pause-for 0` makes); aiorobot's timers want > 0: the shortest one
            timer_period_sec = 1e-9
        timer = super().create_timer(  # type: ignore[misc]
            timer_period_sec, wrapped, callback_group=callback_group, autostart=autostart
        )
        return self._entity(timer, slot, callback_group)

    def create_rate(self, frequency: float, clock: Any = None) -> Rate:  # type: ignore[override]
        if isinstance(frequency, bool) or not isinstance(frequency, (int, float)):
            raise TypeError(f"create_rate: expected a frequency in Hz (a number), found {frequency!r}")
        rate = Rate(frequency, self._context, clock if clock is not None else self.get_clock())
        self._rates_list().append(rate)
        return rate

    def destroy_rate(self, rate: Any) -> bool:  # type: ignore[override]
        """rclpy's: wakes a thread sleeping on ``rate``; ``True`` if it was this node's and not
        destroyed yet."""
        if rate not in self._rates_list() or rate._destroyed:
            return False
        self._rates_list().remove(rate)
        rate.destroy()
        return True

    def _rates_list(self) -> list[Rate]:
        rates = self.__dict__.get("_compat_rates")
        if rates is None:
            rates = self.__dict__["_compat_rates"] = []
        return rates

    def create_service(  # type: ignore[override]
        self, srv_type: Any, srv_name: str, callback: Callable[..., Any], *, qos_profile: Any = None,
        callback_group: Any = None,
    ) -> Any:
        wrapped, slot = self._wrap(callback, callback_group)
        service = super().create_service(  # type: ignore[misc]
            srv_type, srv_name, wrapped, callback_group=callback_group
        )
        return self._entity(service, slot, callback_group)

    def create_client(  # type: ignore[override]
        self, srv_type: Any, srv_name: str, *, qos_profile: Any = None, callback_group: Any = None
    ) -> Any:
        if getattr(self, "_compat_raw", 0):
            return super().create_client(srv_type, srv_name, callback_group=callback_group)  # type: ignore[misc]
        client = Client(
            self, srv_type, self.resolve_topic_name(srv_name, kind="service"),  # type: ignore[attr-defined]
            callback_group or self.default_callback_group,  # type: ignore[attr-defined]
        )
        client._context = self._context
        return add_client(self, client)  # type: ignore[arg-type]

    @property
    def guards(self) -> tuple[Any, ...]:
        return tuple(self._guards_list())

    def _guards_list(self) -> list[Any]:
        guards = self.__dict__.get("_guards")
        if guards is None:
            guards = self.__dict__["_guards"] = []
        return guards

    def get_publishers_info_by_topic(self, topic_name: str, no_mangle: bool = False) -> list[Any]:
        """rclpy's: the topic's publishers in the graph (this process and remote peers)."""
        from .rclpy.topic_endpoint_info import endpoints_of

        return endpoints_of(self, topic_name, "publisher", no_mangle)

    def get_subscriptions_info_by_topic(self, topic_name: str, no_mangle: bool = False) -> list[Any]:
        """rclpy's: the topic's subscriptions in the graph (this process and remote peers)."""
        from .rclpy.topic_endpoint_info import endpoints_of

        return endpoints_of(self, topic_name, "subscription", no_mangle)

    def create_guard_condition(self, callback: Callable[[], Any], callback_group: Any = None) -> Any:
        """A guard condition this node's executor runs ``callback`` for after each ``trigger()``."""
        from .rclpy.guard_condition import GuardCondition

        guard = GuardCondition(callback, callback_group, self._context)
        guard._attach(self)
        self._guards_list().append(guard)
        return guard

    def destroy_guard_condition(self, guard: Any) -> bool:
        """rclpy's: ``True`` if ``guard`` was this node's and is now destroyed."""
        if guard not in self._guards_list():
            return False
        guard.destroy()
        return True

    def __getattr__(self, name: str) -> Any:
        if name in MISSING_NODE_METHODS:
            raise not_provided(f"rclpy.node.Node.{name}")
        raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")


def make_node_class(base: type, name: str, module: str, doc: str) -> type:
    """rclpy's constructor signature over ``base`` (aiorobot's Node or LifecycleNode)."""

    def __init__(
        self: Any, node_name: str, *, context: Context | None = None, cli_args: Sequence[str] | None = None,
        namespace: str | None = None, use_global_arguments: bool = True, enable_rosout: bool = True,
        start_parameter_services: bool = True, parameter_overrides: Any = None,
        allow_undeclared_parameters: bool = False, automatically_declare_parameters_from_overrides: bool = False,
        enable_logger_service: bool = False, **extra: Any,
    ) -> None:
        kwargs = dict(
            enable_rosout=enable_rosout,
            start_parameter_services=start_parameter_services, parameter_overrides=parameter_overrides,
            allow_undeclared_parameters=allow_undeclared_parameters,
            automatically_declare_parameters_from_overrides=automatically_declare_parameters_from_overrides,
            **extra,
        )
        NodeMixin._compat_init(self, node_name, context, cli_args, namespace, use_global_arguments, kwargs, base.__init__)
        if enable_logger_service:
            from ._logger_service import create_logger_services

            create_logger_services(self)

    cls = type(name, (NodeMixin, base), {"__init__": __init__, "__doc__": doc, "__module__": module})
    return cls


def raw(node: Any) -> Any:
    """Context manager: entities created inside are aiorobot's own (callbacks not wrapped)."""
    import contextlib

    @contextlib.contextmanager
    def scope() -> Any:
        node._compat_raw = getattr(node, "_compat_raw", 0) + 1
        try:
            yield
        finally:
            node._compat_raw -= 1

    return scope()


_ = (_actions, _AioNode, _AioRate)
