"""``rclpy.experimental.AsyncNode`` (rclpy 10/11): a node whose callbacks run on the program's asyncio loop.

As rclpy's: ``async with AsyncNode('name') as node:`` (or ``await node.run()`` until
``destroy_node()``); entities made before entering start dispatching on entry; each
subscription, service and timer runs its callbacks one at a time (``concurrent=True``: as
they come); a callback may be ``def`` or ``async def`` and runs as a task of the node's
``TaskGroup``, so one that raises ends the node with an ``ExceptionGroup``; clients are awaited
(``await client.call(request)``, ``await client.wait_for_service()``), the clock sleeps with
``await node.get_clock().sleep(seconds)``.

Beyond rclpy's (which has no actions): ``rclpy.action.ActionServer(node, ...)`` on an
AsyncNode runs its callbacks on the program's loop too, and ``rclpy.action.ActionClient`` on one
awaits: ``await client.wait_for_server()``, ``handle = await client.send_goal_async(goal)``,
``await handle.get_result_async()``, ``await client.send_goal(goal)`` (the result response).

How it runs: docs/rclpy-compat.md; ``_driver`` says which thread runs what.
"""

from __future__ import annotations

import asyncio
import functools
from collections.abc import Callable
from typing import Any

from ...._core import _services
from ...._core._groups import MutuallyExclusiveCallbackGroup, ReentrantCallbackGroup
from ..._context import Context
from ...._core._node import Node as _AioNode
from ....lowlevel import add_client
from ..node import Node
from ._driver import call_user, driver_of, start_on

__all__ = ["AsyncClient", "AsyncClock", "AsyncNode"]


class AsyncClient(_services.Client):
    """A service client of an AsyncNode: ``await client.call(request)``, ``await client.wait_for_service()``."""

    _async_node: AsyncNode

    async def wait_for_service(self, *, check_interval: float = 0.1) -> None:  # type: ignore[override]
        """Until a server is ready (wrap it in ``asyncio.timeout`` for a bound), as rclpy's."""
        while not self.service_is_ready():
            await asyncio.sleep(check_interval)

    async def call(self, request: Any) -> Any:  # type: ignore[override]
        """Send ``request`` and await the response."""
        if self.destroyed:
            raise RuntimeError("Calling a destroyed client is forbidden")
        self._check_request(request)
        loop = self._async_node._context.loop
        if loop is None:
            raise RuntimeError("AsyncClient.call: the context was shut down")
        outcome = asyncio.run_coroutine_threadsafe(_services.Client.call(self, request), loop)
        return await asyncio.wrap_future(outcome)


class AsyncClock:
    """The node's clock with ``await clock.sleep(seconds)`` (sim time too); other calls are the clock's."""

    def __init__(self, node: AsyncNode) -> None:
        self._node = node
        self._pending: set[asyncio.Future[Any]] = set()
        self._destroyed = False

    def __getattr__(self, name: str) -> Any:
        return getattr(_AioNode.get_clock(self._node), name)

    def __repr__(self) -> str:
        return f"<AsyncClock of {self._node.get_fully_qualified_name()}>"

    def _destroy(self) -> None:
        self._destroyed = True
        for fut in list(self._pending):
            fut.cancel()

    async def sleep(self, duration_sec: float) -> None:
        """Sleep ``duration_sec`` on this clock; ``TimeSourceChangedError`` if ROS time is switched meanwhile."""
        from ..exceptions import TimeSourceChangedError

        if self._destroyed:
            raise RuntimeError("Cannot sleep on a destroyed clock")
        if duration_sec <= 0:
            await asyncio.sleep(0)
            return
        clock = _AioNode.get_clock(self._node)
        loop = asyncio.get_running_loop()
        if not clock.ros_time_is_active:
            fut: asyncio.Future[Any] = loop.create_future()
            handle = loop.call_later(duration_sec, lambda: fut.done() or fut.set_result(True))
        else:
            runtime_loop = self._node._context.loop
            assert runtime_loop is not None
            fut = asyncio.wrap_future(asyncio.run_coroutine_threadsafe(clock.sleep_for(duration_sec), runtime_loop))
            handle = None
        self._pending.add(fut)
        try:
            reached = await fut
        finally:
            self._pending.discard(fut)
            if handle is not None:
                handle.cancel()
        if reached is False:
            raise TimeSourceChangedError()


class AsyncNode(Node):  # type: ignore[misc,valid-type]
    """rclpy's ``AsyncNode(node_name, *, context, cli_args, namespace, ...)``: see the module docstring."""

    def __init__(
        self, node_name: str, *, context: Context | None = None, cli_args: list[str] | None = None,
        namespace: str | None = None, use_global_arguments: bool = True, enable_rosout: bool = True,
        rosout_qos_profile: Any = None, start_parameter_services: bool = True, parameter_overrides: Any = None,
        allow_undeclared_parameters: bool = False, automatically_declare_parameters_from_overrides: bool = False,
        enable_logger_service: bool = False,
    ) -> None:
        self._tg: asyncio.TaskGroup | None = None
        self._user_loop: asyncio.AbstractEventLoop | None = None
        self._destroyed_event = asyncio.Event()
        self._in_flight: set[asyncio.Task[Any]] = set()
        #: on the context's loop: futures of callbacks that came before the node was entered
        self._entry_waiters: list[asyncio.Future[None]] = []
        self._entered = False
        super().__init__(
            node_name, context=context, cli_args=cli_args, namespace=namespace,
            use_global_arguments=use_global_arguments, enable_rosout=enable_rosout,
            start_parameter_services=start_parameter_services, parameter_overrides=parameter_overrides,
            allow_undeclared_parameters=allow_undeclared_parameters,
            automatically_declare_parameters_from_overrides=automatically_declare_parameters_from_overrides,
            enable_logger_service=enable_logger_service,
        )
        self._async_clock = AsyncClock(self)

    # -- lifetime -----------------------------------------------------------------------------

    async def __aenter__(self) -> AsyncNode:
        if self._destroyed_event.is_set():
            raise RuntimeError("Node has been destroyed and cannot be reentered")
        if self._tg is not None:
            raise RuntimeError("Node is already running")
        tg = asyncio.TaskGroup()
        self._tg = await tg.__aenter__()
        self._user_loop = asyncio.get_running_loop()
        driver_of(self._context).acquire()
        self._entered = True
        loop = self._context.loop
        if loop is not None and not loop.is_closed():
            loop.call_soon_threadsafe(self._release_entry_waiters)
        return self

    async def __aexit__(self, exc_type: Any, exc: Any, tb: Any) -> None:
        try:
            self.destroy_node()
            if self._tg is not None:
                await self._tg.__aexit__(exc_type, exc, tb)
        finally:
            self._tg = None
            self._entered = False
            thread = driver_of(self._context).release()
            if thread is not None:
                await asyncio.to_thread(thread.join)

    async def run(self) -> None:
        """Run the node until ``destroy_node()``; ``RuntimeError`` when already entered with ``async with``."""
        async with self:
            await self._destroyed_event.wait()

    def destroy_node(self) -> None:
        """Destroy the node and its entities (again: nothing); callbacks in flight are cancelled."""
        if self._destroyed_event.is_set():
            return
        self._destroyed_event.set()
        for task in list(self._in_flight):
            task.cancel()
        self._async_clock._destroy()
        context = self._context
        loop = context.loop
        if loop is not None and loop.is_running() and context._spin_thread is not None:
            # the driver thread runs the loop: take the node out of the graph there
            loop.call_soon_threadsafe(self._destroy_on_loop)
        else:
            self._destroy_on_loop()

    def _destroy_on_loop(self) -> None:
        super().destroy_node()
        self._release_entry_waiters()

    def _release_entry_waiters(self) -> None:
        waiters, self._entry_waiters = self._entry_waiters, []
        for waiter in waiters:
            if not waiter.done():
                waiter.set_result(None)

    def get_clock(self) -> AsyncClock:  # type: ignore[override]
        """The node's clock, with ``await clock.sleep(seconds)``."""
        return self._async_clock

    async def wait_for_node(self, fully_qualified_node_name: str, *, check_interval: float = 0.1) -> None:  # type: ignore[override]
        """Until the node is in the graph (bound it with ``asyncio.timeout``), as rclpy's."""
        if not fully_qualified_node_name.startswith("/"):
            fully_qualified_node_name = "/" + fully_qualified_node_name
        while fully_qualified_node_name not in self.get_fully_qualified_node_names():
            await asyncio.sleep(check_interval)

    # -- callbacks run on the program's loop ------------------------------------------------------

    def _bridge_callback(self, callback: Callable[..., Any] | None) -> Callable[..., Any] | None:
        """``callback`` as the runtime calls it: handed to the program's loop, its result handed back."""
        if callback is None:
            return None
        node = self

        @functools.wraps(callback)
        async def on_runtime_loop(*args: Any, **kwargs: Any) -> Any:
            if not node._entered and not node._destroyed_event.is_set():
                waiter = asyncio.get_running_loop().create_future()
                node._entry_waiters.append(waiter)
                await waiter
            user_loop = node._user_loop
            if node._destroyed_event.is_set() or user_loop is None:
                return None
            return await asyncio.wrap_future(start_on(user_loop, lambda: node._start_callback(callback, args, kwargs)))

        on_runtime_loop._aiorobot_compat_wrapped = True  # type: ignore[attr-defined]
        return on_runtime_loop

    def _start_callback(self, callback: Callable[..., Any], args: tuple[Any, ...], kwargs: dict[str, Any]) -> Any:
        tg = self._tg
        if tg is None or self._destroyed_event.is_set():
            return None
        task = tg.create_task(call_user(callback, args, kwargs))
        self._in_flight.add(task)
        task.add_done_callback(self._in_flight.discard)
        return task

    def _wrap(self, callback: Any, group: Any = None, *, coalesce: bool = False) -> tuple[Any, list[Any]]:
        if getattr(self, "_compat_raw", 0):
            return callback, []  # aiorobot's own entities (parameter services, action internals)
        return self._bridge_callback(callback), []

    def _check_alive(self, what: str) -> None:
        if self._destroyed_event.is_set():
            raise RuntimeError(f"Cannot create {what} on a destroyed node")

    # -- entities (rclpy's AsyncNode signatures) ------------------------------------------------
    # aiorobot's own entities (parameter services, action internals) are made inside raw(node),
    # with aiorobot's keywords: they pass through unchanged.

    def _internal(self) -> bool:
        return bool(getattr(self, "_compat_raw", 0))

    def create_publisher(self, msg_type: Any, topic: str, qos_profile: Any, **internal: Any) -> Any:  # type: ignore[override]
        if not self._internal():
            self._check_alive("publisher")
        return super().create_publisher(msg_type, topic, qos_profile, **internal)

    def create_subscription(  # type: ignore[override]
        self, msg_type: Any, topic: str, callback: Callable[..., Any], qos_profile: Any, *, raw: bool = False,
        concurrent: bool = False, content_filter_options: Any = None, **internal: Any,
    ) -> Any:
        if self._internal():
            return super().create_subscription(msg_type, topic, callback, qos_profile, raw=raw, **internal)
        self._check_alive("subscription")
        if content_filter_options is not None:
            from ..._missing import not_provided

            raise not_provided("rclpy.experimental.AsyncNode.create_subscription(content_filter_options=...)")
        group = ReentrantCallbackGroup() if concurrent else MutuallyExclusiveCallbackGroup()
        return super().create_subscription(msg_type, topic, callback, qos_profile, callback_group=group, raw=raw)

    def create_service(  # type: ignore[override]
        self, srv_type: Any, srv_name: str, callback: Callable[..., Any], *, qos_profile: Any = None,
        concurrent: bool = False, **internal: Any,
    ) -> Any:
        if self._internal():
            return super().create_service(srv_type, srv_name, callback, **internal)
        self._check_alive("service")
        group = ReentrantCallbackGroup() if concurrent else MutuallyExclusiveCallbackGroup()
        return super().create_service(srv_type, srv_name, callback, callback_group=group)

    def create_client(self, srv_type: Any, srv_name: str, *, qos_profile: Any = None, **internal: Any) -> Any:  # type: ignore[override]
        if self._internal():
            return super().create_client(srv_type, srv_name, **internal)
        self._check_alive("client")
        client = AsyncClient(
            self, srv_type, self.resolve_topic_name(srv_name, kind="service"), ReentrantCallbackGroup()
        )
        client._context = self._context
        client._async_node = self
        return add_client(self, client)

    def create_timer(self, timer_period_sec: float, callback: Callable[..., Any], autostart: bool = True, **internal: Any) -> Any:  # type: ignore[override]
        if self._internal():
            return super().create_timer(timer_period_sec, callback, autostart=autostart, **internal)
        self._check_alive("timer")
        return super().create_timer(
            timer_period_sec, callback, callback_group=MutuallyExclusiveCallbackGroup(), autostart=autostart
        )
