"""``Node``: the unit users write. Entity factories, parameters, logging, clock, offloading.

A node can be built before it joins a runtime (entities created in ``__init__``
wait); ``Runtime.add_node`` binds it to a loop — the main loop or the priority
loop — registers its endpoints on the bus and starts its timers and dispatchers
there. Every callback may be ``async def`` or ``def``; it runs under its callback
group, and an exception it raises is logged with the node and entity named while
the node goes on.
"""

from __future__ import annotations

import asyncio
import functools
import inspect
import threading
import time
from collections.abc import Awaitable, Callable, Iterable, Mapping, Sequence
from typing import TYPE_CHECKING, Any, TypeVar

from ._actions import DEFAULT_RESULT_TIMEOUT_SEC, ActionClient, ActionServer
from ._clock import Clock
from ._groups import CallbackGroup, MutuallyExclusiveCallbackGroup, ReentrantCallbackGroup
from ._handoff import post, raise_on
from ._logging import ROSOUT_QOS, NodeLogger
from ._names import join_fqn, resolve_name, validate_namespace, validate_node_name
from ._node_graph import NodeGraphMixin
from ._node_parameters import NodeParametersMixin
from ._parameter_store import ParameterStore
from ._event_handler import PublisherEventCallbacks, SubscriptionEventCallbacks
from ._pubsub import MessageStream, Publisher, Subscription
from ._qos import QoSProfile, to_qos_profile
from ._services import Client, Service
from ._stats import CallbackRecorder, create_statistics_service
from ._time import Time
from ._timer import Rate, Timer
from ._waker import LoopWaker, TimerFdWaker

if TYPE_CHECKING:
    from ._culprit import LateWatch
    from ._runtime import Runtime

__all__ = ["Node"]

#: how often ``on_start`` is retried under ``on_failure = "restart"``
START_RETRIES = 3
#: repeated failures of one callback are logged at most this often (all are counted)
FAILURE_LOG_PERIOD_SEC = 5.0

M = TypeVar("M")
R = TypeVar("R")


class Node(NodeParametersMixin, NodeGraphMixin):
    """A ROS 2 style node, asyncio-native.

    Parameters
    ----------
    name
        The node name (letters, digits, ``_``); a ``__node`` remapping overrides it.
    namespace
        The node's namespace (``"/robot1"``); a ``__ns`` remapping overrides it.
    parameter_overrides
        Values that replace the defaults of parameters this node declares.
    remappings
        Topic and service remappings (``{"/cmd_vel": "/base/cmd_vel"}``), plus the
        special keys ``__node`` and ``__ns`` as in ROS 2.
    cli_args
        ROS arguments as rclpy's: ``["--ros-args", "-p", "rate:=5", "-r", "/a:=/b",
        "--params-file", "f.yaml"]``; file sections match this node's fully qualified name.
    allow_undeclared_parameters, automatically_declare_parameters_from_overrides, start_parameter_services
        As in rclpy: setting undeclared parameters declares them (dynamically typed);
        every override is declared at construction; the ``~/get_parameters`` family of
        services is created. ``/parameter_events`` is always published.
        With the parameter services comes ``~/get_statistics`` (aiorobot's: what ``aiorobot
        top`` reads, see docs/observability.md).
    enable_rosout
        As in rclpy: what the node's logger emits is also published on ``/rosout``
        (``rcl_interfaces/msg/Log``, transient local, depth 1000); ``--disable-rosout-logs``
        in ``cli_args`` turns it off too.

    rclpy difference: the ``use_sim_time`` parameter, when nothing sets it, follows
    ``Runtime(use_sim_time=...)`` instead of defaulting to false, so one runtime flag
    switches every node; ``parameter_overrides`` also takes a ``{name: value}`` mapping; a node
    with parameter services also serves ``~/get_statistics`` (what ``aiorobot top`` reads).
    """

    def __init__(
        self,
        name: str,
        *,
        namespace: str = "",
        parameter_overrides: Mapping[str, Any] | Iterable[Any] | None = None,
        remappings: Mapping[str, str] | None = None,
        allow_undeclared_parameters: bool = False,
        automatically_declare_parameters_from_overrides: bool = False,
        start_parameter_services: bool = True,
        cli_args: Sequence[str] | None = None,
        enable_rosout: bool = True,
    ) -> None:
        from ._node_arguments import resolve_node_arguments

        arguments = resolve_node_arguments(
            name, namespace, parameter_overrides, dict(remappings or {}), cli_args
        )
        remaps = arguments.remappings
        for key, value in remaps.items():
            if not isinstance(key, str) or not isinstance(value, str):
                raise TypeError(f"remappings: expected str -> str, found {key!r} -> {value!r}")
        self._name = validate_node_name(remaps.get("__node", name))
        self._namespace = validate_namespace(remaps.get("__ns", namespace))
        self._remappings = remaps
        self._fqn = join_fqn(self._namespace, self._name)
        self._parameters = ParameterStore(
            self._fqn,
            arguments.overrides,
            allow_undeclared=allow_undeclared_parameters,
            quiet=arguments.quiet,
            sources=arguments.sources,
        )
        self._logger = NodeLogger(self._fqn)
        if arguments.log_level is not None:
            self._logger.set_level(arguments.log_level)
        self._default_group = MutuallyExclusiveCallbackGroup()
        self._publishers: list[Publisher[Any]] = []
        self._subscriptions: list[Subscription[Any]] = []
        self._timers: list[Timer] = []
        self._services: list[Service] = []
        self._clients: list[Client] = []
        self._tasks: set[asyncio.Task[Any]] = set()
        # Bound by Runtime.add_node:
        self._runtime: Runtime | None = None
        self._executor: str | None = None
        self._loop: asyncio.AbstractEventLoop | None = None
        self._thread_id: int | None = None
        self._waker: LoopWaker | TimerFdWaker | None = None
        self._clock: Clock = Clock()
        #: the runtime's culprit watch, for a node on the priority loop (see ``_culprit``)
        self._late_watch: LateWatch | None = None
        self._started = False
        #: callback statistics per entity (see ``_stats``), filled by ``_invoke``
        self._callback_stats: dict[Any, CallbackRecorder] = {}
        #: (start ns, end ns, entity) of the node's last finished callback, for the culprit watch
        self._last_callback: tuple[int, int, Any] | None = None
        self._setup_parameters(automatically_declare_parameters_from_overrides, start_parameter_services)
        if enable_rosout and arguments.rosout is not False:  # --disable-rosout-logs in cli_args
            from ..msgs.rcl_interfaces import Log

            self._logger._attach_rosout(self.create_publisher(Log, "/rosout", ROSOUT_QOS))
        if start_parameter_services:
            create_statistics_service(self)

    def __repr__(self) -> str:
        where = f" on {self._executor}" if self._executor else " (not added)"
        return f"<{type(self).__name__} {self._fqn}{where}>"

    # -- identity ----------------------------------------------------------------

    def get_name(self) -> str:
        return self._name

    def get_namespace(self) -> str:
        return self._namespace

    def get_fully_qualified_name(self) -> str:
        return self._fqn

    @property
    def executor(self) -> str | None:
        """``"main"`` or ``"priority"`` once added to a runtime."""
        return self._executor

    @property
    def runtime(self) -> Runtime:
        if self._runtime is None:
            raise RuntimeError(f"{self!r} is not added to a runtime; call runtime.add_node(node) first")
        return self._runtime

    def resolve_topic_name(self, topic: str, *, kind: str = "topic") -> str:
        """The fully qualified, remapped name ``topic`` refers to from this node."""
        return resolve_name(topic, self._name, self._namespace, self._remappings, kind)

    # -- lifecycle hooks -------------------------------------------------------------

    async def on_start(self) -> None:
        """Called on the node's loop once it runs (open devices, start background work)."""

    def on_added(self) -> None:
        """Called synchronously by ``Runtime.add_node`` once the node belongs to the runtime,
        before its endpoints join the graph and before anything else is added: for extensions
        that must see the graph from its start (a recorder taps publishers added right after it).
        What it raises leaves the node out of the runtime and propagates from ``add_node``."""

    async def on_shutdown(self) -> None:
        """Called once when the runtime shuts down, before anything stops.

        Controllers command zero velocity here; what is published still reaches
        subscribers on either loop before the runtime stops.
        """

    # -- entities ---------------------------------------------------------------------

    def _register(self, entity: Any, entities: list[Any]) -> None:
        """Keep ``entity`` in ``entities`` and, once the node is in a runtime, put it on the bus
        (:meth:`Runtime._bus_add`) and start it if the node has started; an entity the bus refuses
        is not kept."""
        entities.append(entity)
        if self._runtime is None:
            return
        try:
            self._runtime._bus_add(entity)
        except BaseException:
            entities.remove(entity)
            raise
        start = getattr(entity, "_start", None)
        if self._started and start is not None:
            self._call_soon(start)

    def create_publisher(
        self,
        msg_type: type[M],
        topic: str,
        qos: QoSProfile | int,
        *,
        callback_group: CallbackGroup | None = None,
        event_callbacks: PublisherEventCallbacks | None = None,
    ) -> Publisher[M]:
        """A :class:`Publisher` of ``msg_type`` on ``topic``; ``event_callbacks`` get its QoS events
        (deadline missed, liveliness lost, incompatible QoS or type), run in ``callback_group``."""
        _check_msg_type(msg_type)
        pub: Publisher[M] = Publisher(
            self, msg_type, self.resolve_topic_name(topic), to_qos_profile(qos),
            event_callbacks=event_callbacks, callback_group=callback_group or self._default_group,
        )
        self._register(pub, self._publishers)
        return pub

    def create_subscription(
        self,
        msg_type: type[M],
        topic: str,
        callback: Callable[[M], Any],
        qos: QoSProfile | int,
        *,
        callback_group: CallbackGroup | None = None,
        event_callbacks: SubscriptionEventCallbacks | None = None,
        raw: bool = False,
    ) -> Subscription[M]:
        """Call ``callback(msg)`` for each message on ``topic``; a callback that cannot take one
        argument but can take two gets ``(msg, message_info)`` (rclpy's MessageInfo dict).
        ``raw=True`` hands it the message's CDR bytes; ``event_callbacks`` get the QoS events."""
        if not callable(callback):
            raise TypeError(f"subscription callback must be callable, got {callback!r}")
        return self._add_subscription(msg_type, topic, callback, qos, callback_group, event_callbacks, raw)

    def subscribe(self, msg_type: type[M], topic: str, qos: QoSProfile | int = 10) -> MessageStream[M]:
        """Receive a topic as an async iterator: ``async for msg in node.subscribe(T, "/x")``."""
        return MessageStream(self._add_subscription(msg_type, topic, None, qos, None))

    def _add_subscription(
        self,
        msg_type: type[M],
        topic: str,
        callback: Callable[[M], Any] | None,
        qos: QoSProfile | int,
        group: CallbackGroup | None,
        event_callbacks: SubscriptionEventCallbacks | None = None,
        raw: bool = False,
    ) -> Subscription[M]:
        _check_msg_type(msg_type)
        sub: Subscription[M] = Subscription(
            self,
            msg_type,
            self.resolve_topic_name(topic),
            callback,
            to_qos_profile(qos),
            group or self._default_group,
            event_callbacks=event_callbacks,
            raw=raw,
        )
        self._register(sub, self._subscriptions)
        return sub

    def create_timer(
        self,
        period_sec: float,
        callback: Callable[[], Any],
        *,
        callback_group: CallbackGroup | None = None,
        autostart: bool = True,
    ) -> Timer:
        if not callable(callback):
            raise TypeError(f"timer callback must be callable, got {callback!r}")
        timer = Timer(self, period_sec, callback, callback_group or self._default_group, autostart=autostart)
        self._timers.append(timer)
        if self._loop is not None and autostart:
            timer._anchor()
        if self._started and autostart:
            self._call_soon(timer._start)
        return timer

    def create_rate(self, frequency: float) -> Rate:
        """A :class:`Rate` of ``frequency`` Hz on this node's clock; ``TypeError`` for a non-number
        (``create_rate(None)``) and ``ValueError`` for one <= 0, as rclpy."""
        if isinstance(frequency, bool) or not isinstance(frequency, (int, float)):
            raise TypeError(f"create_rate: expected a frequency in Hz (a number), found {frequency!r}")
        return Rate(self, frequency)

    def destroy_rate(self, rate: Rate) -> bool:
        """Retire ``rate`` (rclpy's ``destroy_rate``): a task sleeping on it wakes, sleeping on it
        afterwards raises. ``True`` if it was this node's and not destroyed yet, as rclpy."""
        if rate.node is not self or rate.destroyed:
            return False
        rate.destroy()
        return True

    def destroy_publisher(self, pub: Publisher[Any]) -> bool:
        """Destroy ``pub``; ``True`` if it was this node's (and not destroyed yet), as rclpy."""
        if pub in self._publishers:
            self._publishers.remove(pub)
            pub.destroyed = True
            if self._runtime is not None:
                self._runtime._bus_remove(pub)
            self._call_soon(pub._stop)
            return True
        return False

    def destroy_subscription(self, sub: Subscription[Any]) -> bool:
        """Destroy ``sub``; ``True`` if it was this node's (and not destroyed yet), as rclpy."""
        if sub in self._subscriptions:
            self._subscriptions.remove(sub)
            if self._runtime is not None:
                self._runtime._bus_remove(sub)
            self._call_soon(self._close_subscription, sub)
            return True
        return False

    @staticmethod
    def _close_subscription(sub: Subscription[Any]) -> None:
        sub.destroyed = True
        if sub._deadline is not None:
            sub._deadline.stop()
        if sub._task is not None:
            sub._task.cancel()
        waiter = sub._waiter
        if waiter is not None and not waiter.done():
            waiter.set_result(None)

    def destroy_timer(self, timer: Timer) -> bool:
        """Destroy ``timer``; ``True`` if it was this node's (and not destroyed yet), as rclpy."""
        if timer in self._timers:
            self._timers.remove(timer)
            timer.destroyed = True
            timer._cancelled = True
            self._call_soon(self._close_timer, timer)
            return True
        return False

    def _close_timer(self, timer: Timer) -> None:
        if timer._task is not None:
            timer._task.cancel()
        if self._late_watch is not None:
            self._late_watch.disarm(id(timer))

    def create_service(
        self,
        srv_type: Any,
        srv_name: str,
        callback: Callable[..., Any],
        *,
        callback_group: CallbackGroup | None = None,
    ) -> Service:
        """Serve ``srv_name`` with ``callback(request) -> response`` (async or sync).

        rclpy's ``callback(request, response) -> response`` form works too (a callback
        taking two positional arguments gets a fresh ``Response``). A callback that
        raises answers the caller with :class:`ServiceError` carrying the reason.
        The parameter names are rclpy's.
        """
        service = Service(
            self, srv_type, self.resolve_topic_name(srv_name, kind="service"), callback, callback_group or self._default_group
        )
        self._register(service, self._services)
        return service

    def create_client(
        self, srv_type: Any, srv_name: str, *, callback_group: CallbackGroup | None = None
    ) -> Client:
        """A client of ``srv_name``: ``await client.wait_for_service()``, ``await client.call(request)``.

        ``client.call_async(request)`` returns an rclpy-style future. ``callback_group``
        is kept on the client as in rclpy; responses complete on the caller's loop,
        which needs no group to serialise them.
        """
        client = Client(
            self, srv_type, self.resolve_topic_name(srv_name, kind="service"), callback_group or self._default_group
        )
        self._register(client, self._clients)
        return client

    def create_action_server(
        self,
        action_type: Any,
        name: str,
        execute: Callable[[Any], Any],
        *,
        goal_callback: Callable[[Any], Any] | None = None,
        handle_accepted_callback: Callable[[Any], Any] | None = None,
        cancel_callback: Callable[[Any], Any] | None = None,
        callback_group: CallbackGroup | None = None,
        result_timeout: float = DEFAULT_RESULT_TIMEOUT_SEC,
    ) -> ActionServer:
        """Serve action ``name``: ``execute(goal_handle) -> Result`` per accepted goal.

        ``handle_accepted_callback(goal_handle)`` replaces the default start (``goal_handle.execute()``)
        for servers that queue or preempt goals; ``result_timeout`` is how long a finished goal's
        result is kept, in seconds. See :class:`ActionServer`.
        """
        return ActionServer(
            self,
            action_type,
            name,
            execute,
            goal_callback=goal_callback,
            handle_accepted_callback=handle_accepted_callback,
            cancel_callback=cancel_callback,
            callback_group=callback_group,
            result_timeout=result_timeout,
        )

    def create_action_client(
        self, action_type: Any, name: str, *, callback_group: CallbackGroup | None = None
    ) -> ActionClient:
        """A client of action ``name``: ``handle = await client.send_goal(goal)``."""
        return ActionClient(self, action_type, name, callback_group=callback_group)

    def destroy_service(self, service: Service) -> bool:
        """Destroy ``service``; ``True`` if it was this node's (and not destroyed yet), as rclpy."""
        if service in self._services:
            self._services.remove(service)
            if self._runtime is not None:
                self._runtime._bus_remove(service)
            self._call_soon(service._close)
            return True
        return False

    def destroy_client(self, client: Client) -> bool:
        """Destroy ``client``; ``True`` if it was this node's (and not destroyed yet), as rclpy."""
        if client in self._clients:
            self._clients.remove(client)
            client.destroyed = True
            if self._runtime is not None:
                self._runtime._bus_remove(client)
            return True
        return False

    def destroy_node(self) -> None:
        """Take the node out of the graph, as rclpy's ``destroy_node``; calling it again does nothing.

        A node in a runtime is removed from it (its endpoints leave at once, its tasks end
        on its loop); a node never added has its publishers, subscriptions, timers,
        services and clients destroyed.
        """
        runtime = self._runtime
        if runtime is not None and self in runtime._nodes:
            runtime.remove_node(self)
        for pub in list(self._publishers):
            self.destroy_publisher(pub)
        for sub in list(self._subscriptions):
            self.destroy_subscription(sub)
        for timer in list(self._timers):
            self.destroy_timer(timer)
        for service in list(self._services):
            self.destroy_service(service)
        for client in list(self._clients):
            self.destroy_client(client)

    @property
    def publishers(self) -> tuple[Publisher[Any], ...]:
        return tuple(self._publishers)

    @property
    def subscriptions(self) -> tuple[Subscription[Any], ...]:
        return tuple(self._subscriptions)

    @property
    def timers(self) -> tuple[Timer, ...]:
        return tuple(self._timers)

    @property
    def services(self) -> tuple[Service, ...]:
        """This node's services, as rclpy's ``Node.services``."""
        return tuple(self._services)

    @property
    def clients(self) -> tuple[Client, ...]:
        """This node's service clients, as rclpy's ``Node.clients``."""
        return tuple(self._clients)

    @property
    def default_callback_group(self) -> CallbackGroup:
        """The group of entities created without one (mutually exclusive), as rclpy's."""
        return self._default_group

    # -- logging and time -----------------------------------------------------------------

    def get_logger(self) -> NodeLogger:
        return self._logger

    def get_clock(self) -> Clock:
        return self._clock

    def now(self) -> Time:
        return self._clock.now()

    # -- work elsewhere -------------------------------------------------------------------

    async def offload(self, fn: Callable[..., R], *args: Any, **kwargs: Any) -> R:
        """Run a picklable ``fn(*args, **kwargs)`` in the runtime's process pool.

        Large numpy arrays in the arguments and the result (images, clouds) cross in
        shared memory, not through the pool's pipe. A script that offloads needs the
        ``if __name__ == "__main__":`` guard: the pool starts workers with forkserver.
        """
        from . import _offload

        pool = self.runtime._process_pool()
        payload, segments = _offload.dumps((fn, args, kwargs))
        try:
            future = pool.submit(_offload.run_call, payload)
        except BaseException:
            _offload.release(segments)
            raise
        try:
            data = await asyncio.wrap_future(future)
        except asyncio.CancelledError:
            future.add_done_callback(_discard_result)  # still frees its result's segments
            raise
        finally:
            _offload.release(segments)  # what the worker did not receive (a failed call)
        result: R = _offload.loads(data)
        return result

    async def run_in_thread(self, fn: Callable[..., R], *args: Any, **kwargs: Any) -> R:
        """Run ``fn`` in the runtime's thread pool: for kernels that release the GIL (OpenCV, Numba)."""
        pool = self.runtime._thread_pool()
        return await asyncio.get_running_loop().run_in_executor(pool, functools.partial(fn, *args, **kwargs))

    # -- runtime plumbing (private) ----------------------------------------------------------

    def _bind(
        self,
        runtime: Runtime,
        executor: str,
        loop: asyncio.AbstractEventLoop,
        thread_id: int,
        waker: LoopWaker | TimerFdWaker,
    ) -> None:
        self._runtime = runtime
        self._executor = executor
        self._loop = loop
        self._thread_id = thread_id
        self._waker = waker
        self._clock = self._time_source.clock_for(runtime)
        self._late_watch = runtime.late_watch if executor == "priority" else None
        self._logger._bind_clock(self._clock)
        for timer in self._timers:
            if not timer._cancelled:
                timer._anchor()

    def _unbind(self) -> None:
        self._runtime = None
        self._executor = None
        self._loop = None
        self._thread_id = None
        self._waker = None
        self._late_watch = None
        self._started = False

    def _call_soon(self, fn: Callable[..., Any], *args: Any) -> None:
        """Run ``fn(*args)`` on this node's loop: now if we are on it, else thread-safely."""
        loop = self._loop
        if loop is None:
            fn(*args)
        elif threading.get_ident() == self._thread_id:
            fn(*args)
        else:
            post(loop, fn, *args)

    def create_task(self, coro: Awaitable[Any], *, name: str | None = None) -> asyncio.Task[Any]:
        """Run ``coro`` as a task of this node, on its loop (call it from that loop).

        Unlike ``asyncio.create_task``, the node keeps the task: removing the node or shutting
        the runtime down cancels it and waits for it. ``RuntimeError`` before the node is added.
        ``sys.exit()`` in the task ends the program as in a callback of the node (on the main
        loop, also from the priority loop); the task then returns None.
        """
        return self._create_task(self._exiting(coro) if self._loop is not None else coro, name=name)

    def _create_task(self, coro: Awaitable[Any], *, name: str | None = None) -> asyncio.Task[Any]:
        """:meth:`create_task` for the core's entities, whose callbacks run under :meth:`_invoke`."""
        if self._loop is None:
            if inspect.iscoroutine(coro):
                coro.close()
            raise RuntimeError(f"create_task: {self!r} is not added to a runtime; call runtime.add_node(node) first")
        task: asyncio.Task[Any] = self._loop.create_task(coro, name=name)  # type: ignore[arg-type]
        self._tasks.add(task)
        task.add_done_callback(self._tasks.discard)
        return task

    async def _exiting(self, coro: Awaitable[Any]) -> Any:
        try:
            return await coro
        except SystemExit as exc:
            self._end_program(exc)
            return None

    def _start(self) -> None:
        """Start dispatchers and timers (on the node's loop), then ``on_start``."""
        if self._started:
            return
        self._started = True
        for pub in self._publishers:
            pub._start()
        for sub in self._subscriptions:
            sub._start()
        for timer in self._timers:
            if not timer._cancelled:
                timer._start()
        for service in self._services:
            service._start()
        self._create_task(self._run_on_start(), name=f"on_start {self._fqn}")

    async def _run_on_start(self) -> None:
        """``on_start``; a failure is reported to the runtime, which applies ``on_failure``.

        ``"stop"`` (the default) stops the run, ``"continue"`` leaves the node's callbacks
        running, ``"restart"`` runs ``on_start`` again (at most :data:`START_RETRIES` times,
        one second apart) before reporting the failure.
        """
        attempt = 0
        while True:
            try:
                err = await self._run_hook(self.on_start, "on_start")
            except SystemExit as exc:  # the program ends, as for a callback's
                self._end_program(exc)
                return
            if err is None:
                return
            attempt += 1
            if getattr(self, "_on_failure", "stop") == "restart" and attempt <= START_RETRIES:
                self._logger.warning(f"restarting on_start of {self._fqn} (attempt {attempt} of {START_RETRIES})")
                await asyncio.sleep(1.0)
                continue
            runtime = self._runtime
            if runtime is not None:
                runtime._record_failed_start(self, err)
            return

    async def _run_hook(self, hook: Callable[[], Any], what: str) -> BaseException | None:
        """Run a lifecycle hook; log and return (never raise) what it raises."""
        try:
            result = hook()
            if inspect.isawaitable(result):
                await result
        except asyncio.CancelledError:
            raise
        except Exception as err:
            self._report_failure(what, err)
            return err
        return None

    def _report_failure(self, what: str, err: BaseException) -> None:
        """Count a failure; log the first of each entity with its traceback, repeats throttled."""
        runtime = self._runtime
        count, log_now = runtime._record_failure(self._fqn, what) if runtime is not None else (1, True)
        if count == 1:
            self._logger.error(f"{what} of {self._fqn} raised", exc_info=True)
        elif log_now:
            self._logger.error(
                f"{what} of {self._fqn} raised again ({count} times so far; "
                f"repeats are logged every {FAILURE_LOG_PERIOD_SEC:g} s): {type(err).__name__}: {err}"
            )

    async def _stop(self) -> None:
        """Cancel every task of this node and wait for them (on the node's loop)."""
        for sub in list(self._subscriptions):
            self._close_subscription(sub)
        for service in list(self._services):
            service._close()
        current = asyncio.current_task()
        tasks = [t for t in self._tasks if t is not current]
        for task in tasks:
            task.cancel()
        if tasks:
            await asyncio.gather(*tasks, return_exceptions=True)
        self._started = False

    def _idle(self) -> bool:
        return all(sub.is_idle() for sub in self._subscriptions) and all(
            service.is_idle() for service in self._services
        )

    async def _wait_with_timeout(self, aw: Awaitable[R], timeout_sec: float | None) -> R:
        """Await ``aw``; ``TimeoutError`` after ``timeout_sec`` on the node clock (sim time too)."""
        if timeout_sec is None:
            return await aw
        if isinstance(timeout_sec, bool) or not isinstance(timeout_sec, (int, float)) or timeout_sec < 0:
            raise ValueError(f"timeout_sec: expected a number >= 0 or None, got {timeout_sec!r}")
        clock = self._clock
        if not clock.use_sim_time:
            async with asyncio.timeout(timeout_sec):
                return await aw
        loop = asyncio.get_running_loop()
        work = asyncio.ensure_future(aw)
        deadline = clock.now_ns() + round(timeout_sec * 1e9)
        try:
            while True:
                alarm: asyncio.Future[None] = loop.create_future()
                clock.add_waiter(deadline, alarm)
                await asyncio.wait((work, alarm), return_when=asyncio.FIRST_COMPLETED)
                if work.done():
                    alarm.cancel()
                    return work.result()
                if alarm.exception() if not alarm.cancelled() else None:  # sim time jumped back
                    deadline = clock.now_ns() + round(timeout_sec * 1e9)
                    continue
                raise TimeoutError(f"timed out after {timeout_sec} s of sim time")
        finally:
            if not work.done():
                work.cancel()

    def _record_callback(self, entity: Any, start_ns: int) -> None:
        """Count one callback of ``entity`` that started at ``start_ns`` (``time.monotonic_ns``)."""
        end = time.monotonic_ns()
        recorder = self._callback_stats.get(entity)
        if recorder is None:
            recorder = self._callback_stats[entity] = CallbackRecorder()
        recorder.add(end - start_ns)
        self._last_callback = (start_ns, end, entity)

    async def _invoke(
        self,
        entity: Any,
        group: CallbackGroup,
        fn: Callable[..., Any],
        *args: Any,
        start_deadline: int | None = None,
    ) -> Any:
        """Run one callback under its group, its duration counted against ``entity``; log (never
        raise) what it raises. One coroutine per callback: this is every message's and tick's path."""
        try:
            lock = group._group_lock
            if lock is None and group.exclusive:  # a group class of one's own, with its own __aenter__
                async with group:
                    return await self._invoke(entity, _UNLOCKED, fn, *args, start_deadline=start_deadline)
            if lock is not None and not lock.try_acquire():  # free: taken at once, no coroutine
                await lock.acquire()
            try:
                if start_deadline is not None:
                    entity._record_start(start_deadline)
                start = time.monotonic_ns()
                try:
                    result = fn(*args)
                    if result is not None and inspect.isawaitable(result):
                        result = await result
                finally:
                    self._record_callback(entity, start)
                return result
            finally:
                if lock is not None:
                    lock.release()
        except asyncio.CancelledError:
            raise
        except SystemExit as exc:
            self._end_program(exc)
            return None
        except Exception as err:
            self._report_failure(f"callback of {_describe(entity)}", err)
            return None

    def _end_program(self, exc: SystemExit) -> None:
        """``sys.exit()`` in a callback: raised on the main loop, where asyncio ends the program
        with it as with any callback's there, also when the callback ran on the priority loop (whose
        thread it would end silently). The entity goes on running until the runtime shuts down."""
        runtime = self._runtime
        loop = runtime._loop if runtime is not None else None
        if loop is None or loop.is_closed():
            raise exc
        raise_on(loop, exc)


    def _invoke_now(self, entity: Any, lock: Any, fn: Callable[..., Any], arg: Any, done: Callable[[Any], Any]) -> None:
        """:meth:`_invoke` without a coroutine, for a plain-function callback run at once
        (``deliver_eagerly``): ``lock``, the group's, is held already (None: a lockless group) and
        released here, then ``done(None)`` is called. A callback that returns an awaitable after
        all is awaited in a task, which releases and calls ``done`` when it ends."""
        start = time.monotonic_ns()
        try:
            result = fn(arg)
        except BaseException as err:
            self._record_callback(entity, start)
            if lock is not None:
                lock.release()
            done(None)
            if isinstance(err, SystemExit):
                self._end_program(err)
            elif not isinstance(err, Exception):
                raise
            else:
                self._report_failure(f"callback of {_describe(entity)}", err)  # logged, as _invoke does
            return
        if result is not None and inspect.isawaitable(result):
            self._create_task(self._finish_now(entity, lock, result, start, done), name=f"callback of {_describe(entity)}")
            return
        self._record_callback(entity, start)
        if lock is not None:
            lock.release()
        done(None)

    async def _finish_now(self, entity: Any, lock: Any, result: Awaitable[Any], start: int, done: Callable[[Any], Any]) -> None:
        """The rest of a callback :meth:`_invoke_now` started that returned an awaitable."""
        try:
            await result
        except asyncio.CancelledError:
            raise
        except SystemExit as exc:
            self._end_program(exc)
        except Exception as err:  # noqa: BLE001
            self._report_failure(f"callback of {_describe(entity)}", err)
        finally:
            self._record_callback(entity, start)
            if lock is not None:
                lock.release()
            done(None)


#: What :meth:`Node._invoke` runs a callback of a lockless group's own class under, inside its ``async with``.
_UNLOCKED = ReentrantCallbackGroup()


def _discard_result(future: Any) -> None:
    """Unpickle and drop the result of an offloaded call nobody awaits, freeing its shared memory."""
    if not future.cancelled() and future.exception() is None:
        from . import _offload

        _offload.loads(future.result())


def _describe(entity: Any) -> str:
    if isinstance(entity, Subscription):
        return f"subscription {entity.topic_name}"
    if isinstance(entity, Timer):
        return f"timer {entity.period_ns / 1e9:g}s"
    return repr(entity)


def _check_msg_type(msg_type: Any) -> None:
    if not isinstance(msg_type, type):
        raise TypeError(f"expected a message class (e.g. aiorobot.msgs.geometry_msgs.Twist), got {msg_type!r}")
