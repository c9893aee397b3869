"""Services in one process: servers, clients, and the registry that connects them.

A call hands the request object to the server's node loop (zero-copy, like
topics), the handler runs under its callback group, and the response — or the
reason the handler failed — comes back on the caller's loop. Every call has its
own future, so concurrent calls are matched to their callers by construction; a
caller that timed out has its future cancelled and a late reply is dropped.
"""

from __future__ import annotations

import asyncio
import contextvars
import inspect
import threading
import time
import uuid
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from ._handoff import call_on, wake
from ._errors import ServiceError
from ._future import Future, future_of
from ._service_introspection import ServiceIntrospection

if TYPE_CHECKING:
    from ._groups import CallbackGroup
    from ._node import Node

__all__ = ["Client", "Service", "ServiceRegistry", "ServiceUnavailableError"]


class ServiceUnavailableError(ServiceError):
    """No server offers the service (``wait_for_service`` first)."""


def _srv_name(srv_type: Any) -> str:
    return str(getattr(srv_type, "__msgtype__", None) or getattr(srv_type, "__name__", repr(srv_type)))


def takes_response(handler: Callable[..., Any]) -> bool:
    """Whether ``handler`` is rclpy's ``cb(request, response)`` form rather than ``cb(request)``.

    Two or more positional parameters without defaults (or ``*args``) mean the
    two-argument form; a handler whose signature cannot be read is called with one.
    """
    try:
        sig = inspect.signature(handler)
    except (TypeError, ValueError):
        return False
    required = 0
    for p in sig.parameters.values():
        if p.kind is inspect.Parameter.VAR_POSITIONAL:
            return True
        if p.kind in (inspect.Parameter.POSITIONAL_ONLY, inspect.Parameter.POSITIONAL_OR_KEYWORD):
            if p.default is inspect.Parameter.empty:
                required += 1
    return required >= 2


def check_srv_type(srv_type: Any) -> None:
    if not (isinstance(srv_type, type) and hasattr(srv_type, "Request") and hasattr(srv_type, "Response")):
        raise TypeError(
            f"expected a service type with .Request and .Response (e.g. aiorobot.msgs.std_srvs.Trigger), got {srv_type!r}"
        )


# service_msgs/ServiceEventInfo's event types
_REQUEST_SENT, _REQUEST_RECEIVED, _RESPONSE_SENT, _RESPONSE_RECEIVED = range(4)


@dataclass
class _Call:
    request: Any
    loop: asyncio.AbstractEventLoop
    future: asyncio.Future[Any]
    #: the calling client's GID and the call's sequence number (what introspection events carry)
    client_gid: bytes = bytes(16)
    sequence_number: int = 0
    #: run on the caller's loop once the reply is handed on (see after_reply)
    after: list[Callable[[], object]] = field(default_factory=list)


#: the call whose handler runs in this task (so the handler can act after its reply, see after_reply)
_CURRENT_CALL: contextvars.ContextVar[_Call | None] = contextvars.ContextVar("aiorobot_service_call", default=None)


def after_reply(fn: Callable[[], object]) -> bool:
    """From inside a service handler: call ``fn()`` once the handler's reply is on its way.

    ``fn`` runs on the caller's loop after everything the reply set in motion there (the
    local caller's wake-up, a transport's send of a remote reply): what an action server
    needs to start executing a goal only after its client has the answer, as rclpy sends
    the goal response before it schedules execute. ``False`` outside a handler (then
    nothing is registered).
    """
    call = _CURRENT_CALL.get()
    if call is None:
        return False
    call.after.append(fn)
    return True


class _ServiceEndpoint:
    """What servers and clients share: a node, a service type and a name."""

    node: Node
    srv_type: Any
    srv_name: str

    @property
    def type_name(self) -> str:
        return _srv_name(self.srv_type)

    @property
    def node_name(self) -> str:
        return self.node.get_fully_qualified_name()

    @property
    def service_name(self) -> str:
        """The resolved service name (rclpy's ``service_name``)."""
        return self.srv_name

    _introspection: ServiceIntrospection | None = None

    def __enter__(self) -> Any:
        return self

    def __exit__(self, *exc: object) -> None:
        self.destroy()  # type: ignore[attr-defined]

    def configure_introspection(self, clock: Any, service_event_pub_qos: Any, introspection_state: Any) -> None:
        """Publish this endpoint's calls on ``<service>/_service_event`` (rclpy's; see
        :mod:`aiorobot._core._service_introspection`): ``ServiceIntrospectionState`` OFF, METADATA or CONTENTS."""
        if self._introspection is None:
            self._introspection = ServiceIntrospection(self)
        self._introspection.configure(clock, service_event_pub_qos, introspection_state)

    def _event(self, event_type: int, client_gid: bytes, sequence_number: int, request: Any = None, response: Any = None) -> None:
        if self._introspection is not None:
            self._introspection.emit(event_type, client_gid, sequence_number, request, response)


class Service(_ServiceEndpoint):
    """Answers requests with ``handler(request) -> response``; created by ``Node.create_service``.

    rclpy's form ``handler(request, response) -> response`` works too: a handler
    taking two positional arguments gets a fresh ``Response`` to fill and return.

    rclpy difference: a handler that raises, or returns something other than the
    ``Response``, answers the caller with :class:`~aiorobot.ServiceError` carrying
    the reason; in rclpy the error surfaces in the server's executor and the caller
    never gets an answer.
    """

    kind = "service"

    def __init__(self, node: Node, srv_type: Any, name: str, handler: Callable[[Any], Any], group: CallbackGroup) -> None:
        check_srv_type(srv_type)
        if not callable(handler):
            raise TypeError(f"service handler must be callable, got {handler!r}")
        self.node = node
        self.srv_type = srv_type
        self.srv_name = name
        self.handler = handler
        self._with_response = takes_response(handler)
        self.callback_group = group
        self._queue: deque[_Call] = deque()
        self._waiter: asyncio.Future[None] | None = None
        self._task: asyncio.Task[None] | None = None
        self._busy = 0
        self.destroyed = False
        self.handled = 0
        #: True for a service whose handler only waits for other work to finish (an action's
        #: ``get_result``): a call in progress then does not count as work for ``settle()``.
        self.waits_on_others = False

    def __repr__(self) -> str:
        return f"<Service {self.srv_name} {self.type_name} of {self.node_name} queued={len(self._queue)}>"

    def is_idle(self) -> bool:
        return not self._queue and (self._busy == 0 or self.waits_on_others)

    def _enqueue(self, call: _Call) -> None:
        """Queue a call (on the server node's loop)."""
        if self.destroyed:
            _reply(call, exc=ServiceUnavailableError(f"service {self.srv_name} went away"))
            return
        self._queue.append(call)
        waiter = self._waiter
        if waiter is not None:
            self._waiter = None
            if not waiter.done():
                waiter.set_result(None)

    def _start(self) -> None:
        if self._task is None:
            self._task = self.node._create_task(self._dispatch(), name=f"service {self.srv_name}")

    async def _dispatch(self) -> None:
        loop = self.node._loop
        assert loop is not None
        while True:
            if not self._queue:
                self._waiter = loop.create_future()
                await self._waiter
                continue
            call = self._queue.popleft()
            if call.future.done():  # the caller gave up already
                continue
            self._busy += 1
            if self.callback_group.exclusive:
                try:
                    await self._handle(call)
                finally:
                    self._busy -= 1
            else:
                task = self.node._create_task(self._handle(call), name=f"service {self.srv_name} call")
                task.add_done_callback(self._done)

    def _done(self, _task: asyncio.Task[None]) -> None:
        self._busy -= 1

    async def _handle(self, call: _Call) -> None:
        self._event(_REQUEST_RECEIVED, call.client_gid, call.sequence_number, request=call.request)
        token = _CURRENT_CALL.set(call)
        try:
            async with self.callback_group:
                start = time.monotonic_ns()
                try:
                    if self._with_response:
                        response = self.handler(call.request, self.srv_type.Response())
                    else:
                        response = self.handler(call.request)
                    if inspect.isawaitable(response):
                        response = await response
                finally:
                    self.node._record_callback(self, start)
        except asyncio.CancelledError:
            _reply(call, exc=ServiceError(f"service {self.srv_name} was shut down while handling the call"))
            raise
        except SystemExit as exc:  # the program ends, as for a callback's; the caller is told
            _reply(call, exc=ServiceError(f"service {self.srv_name}: its handler ended the program (sys.exit)"))
            self.node._end_program(exc)
            return
        except Exception as err:
            self.node.get_logger().error(f"handler of service {self.srv_name} raised", exc_info=True)
            _reply(call, exc=ServiceError(f"service {self.srv_name} failed: {type(err).__name__}: {err}"))
            return
        finally:
            _CURRENT_CALL.reset(token)
        self.handled += 1
        if not isinstance(response, self.srv_type.Response):
            _reply(
                call,
                exc=ServiceError(
                    f"service {self.srv_name}: the handler returned {type(response).__name__}, "
                    f"expected {_srv_name(self.srv_type.Response)}"
                ),
            )
            return
        self._event(_RESPONSE_SENT, call.client_gid, call.sequence_number, response=response)
        _reply(call, result=response)

    def _close(self) -> None:
        self.destroyed = True
        while self._queue:
            _reply(self._queue.popleft(), exc=ServiceUnavailableError(f"service {self.srv_name} went away"))
        if self._task is not None:
            self._task.cancel()

    def destroy(self) -> None:
        self.node.destroy_service(self)


def _reply(call: _Call, *, result: Any = None, exc: BaseException | None = None) -> None:
    def deliver() -> None:
        if not call.future.done():  # else timed out or cancelled: the late reply is dropped
            if exc is not None:
                call.future.set_exception(exc)
            else:
                call.future.set_result(result)
        for fn in call.after:  # queued behind the callbacks the result just scheduled
            call.loop.call_soon(fn)

    call_on(call.loop, deliver)


class Client(_ServiceEndpoint):
    """Calls a service; created by ``Node.create_client``.

    ``await client.call(request)`` is the asyncio way; ``client.call_async(request)``
    returns an rclpy-style :class:`~aiorobot.Future`.

    rclpy difference: ``call`` and ``wait_for_service`` are coroutines (rclpy's
    block the calling thread), and a call (``call`` or ``call_async``) when no
    server offers the service fails at once with :class:`ServiceUnavailableError`
    instead of waiting unanswered; wait with ``await client.wait_for_service()``
    first, as rclpy's examples do.
    """

    kind = "client"

    def __init__(self, node: Node, srv_type: Any, name: str, callback_group: CallbackGroup | None = None) -> None:
        check_srv_type(srv_type)
        self.node = node
        self.srv_type = srv_type
        self.srv_name = name
        self.callback_group = callback_group
        self.destroyed = False
        self._pending: set[asyncio.Future[Any]] = set()
        #: as rmw's: a GID for this client, and sequence numbers of its calls from 1
        self.gid = uuid.uuid4().bytes
        self._sequence = 0

    def __repr__(self) -> str:
        return f"<Client {self.srv_name} {self.type_name} of {self.node_name} pending={len(self._pending)}>"

    def _registry(self) -> ServiceRegistry:
        return self.node.runtime._bus.services

    def service_is_ready(self) -> bool:
        return self.node._runtime is not None and bool(self._registry().servers(self.srv_name, self.type_name))

    async def wait_for_service(self, timeout_sec: float | None = None) -> bool:
        """True once a server offers the service; False after ``timeout_sec`` (node clock)."""
        registry = self._registry()
        fut = asyncio.get_running_loop().create_future()
        registry.add_waiter(self.srv_name, self.type_name, fut)
        try:
            await self.node._wait_with_timeout(fut, timeout_sec)
            return True
        except TimeoutError:
            return False
        finally:
            registry.remove_waiter(self.srv_name, fut)

    def _check_request(self, request: Any) -> None:
        if self.destroyed:
            raise RuntimeError(f"{self!r} was destroyed")
        if not isinstance(request, self.srv_type.Request):
            raise TypeError(
                f"client of {self.srv_name} expects {_srv_name(self.srv_type.Request)}, got {type(request).__name__}"
            )

    def call_async(self, request: Any) -> Future[Any]:
        """Send ``request``; the returned :class:`~aiorobot.Future` completes with the response.

        As rclpy's ``call_async``: ``future.add_done_callback(cb)``, ``future.result()``,
        ``future.done()``, or ``await future``. The future holds the errors
        :meth:`call` would raise. ``future.cancel()`` abandons the call (a late
        reply is dropped). Call it from a callback or coroutine, or once the node
        runs (then from any thread).
        """
        self._check_request(request)
        return future_of(self.call(request), None if _in_loop() else self.node._loop)

    def remove_pending_request(self, future: Future[Any]) -> None:
        """Abandon a ``call_async`` request (rclpy's): its future is cancelled, a late reply dropped."""
        future.cancel()

    async def call(self, request: Any, timeout_sec: float | None = None) -> Any:
        """Send ``request`` and return the response.

        Raises ``TimeoutError`` after ``timeout_sec`` (on the node clock),
        :class:`ServiceError` with the server's reason when its handler fails, and
        :class:`ServiceUnavailableError` at once when no server offers the service.
        """
        self._check_request(request)
        servers = self._registry().servers(self.srv_name, self.type_name)
        if not servers:
            raise ServiceUnavailableError(
                f"no server for service {self.srv_name} [{self.type_name}]; await client.wait_for_service() first"
            )
        loop = asyncio.get_running_loop()
        fut: asyncio.Future[Any] = loop.create_future()
        server = servers[0]
        self._pending.add(fut)
        self._sequence += 1
        sequence = self._sequence
        try:
            self._event(_REQUEST_SENT, self.gid, sequence, request=request)
            server.node._call_soon(server._enqueue, _Call(request, loop, fut, self.gid, sequence))
            try:
                response = await self.node._wait_with_timeout(fut, timeout_sec)
                self._event(_RESPONSE_RECEIVED, self.gid, sequence, response=response)
                return response
            except TimeoutError:
                raise TimeoutError(
                    f"service {self.srv_name} did not answer within {timeout_sec} s"
                ) from None
        finally:
            self._pending.discard(fut)
            if not fut.done():
                fut.cancel()

    def destroy(self) -> None:
        self.node.destroy_client(self)


def _in_loop() -> bool:
    try:
        asyncio.get_running_loop()
    except RuntimeError:
        return False
    return True


@dataclass
class _Entry:
    servers: list[Service] = field(default_factory=list)
    clients: list[Client] = field(default_factory=list)
    waiters: list[tuple[str, asyncio.Future[None]]] = field(default_factory=list)


class ServiceRegistry:
    """Which servers and clients exist for each service name (thread-safe)."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._entries: dict[str, _Entry] = {}
        #: A transport told of every server and client added or removed (set by the transport).
        self.listener: Any = None

    def add(self, endpoint: Service | Client) -> None:
        with self._lock:
            entry = self._entries.setdefault(endpoint.srv_name, _Entry())
            if endpoint.kind == "service":  # a local Service or a transport's remote server
                entry.servers.append(endpoint)
                ready = [fut for t, fut in entry.waiters if t == endpoint.type_name]
                entry.waiters = [(t, f) for t, f in entry.waiters if t != endpoint.type_name]
            else:
                entry.clients.append(endpoint)
                ready = []
        for fut in ready:
            call_on(fut.get_loop(), wake, fut)
        if self.listener is not None:
            self.listener.endpoint_added(endpoint)

    def remove(self, endpoint: Service | Client) -> None:
        with self._lock:
            entry = self._entries.get(endpoint.srv_name)
            if entry is None:
                return
            for group in (entry.servers, entry.clients):
                if endpoint in group:
                    group.remove(endpoint)  # type: ignore[arg-type]
            if not entry.servers and not entry.clients and not entry.waiters:
                del self._entries[endpoint.srv_name]
        if self.listener is not None:
            self.listener.endpoint_removed(endpoint)

    def servers(self, name: str, type_name: str | None = None) -> list[Service]:
        with self._lock:
            entry = self._entries.get(name)
            if entry is None:
                return []
            return [s for s in entry.servers if type_name is None or s.type_name == type_name]

    def add_waiter(self, name: str, type_name: str, fut: asyncio.Future[None]) -> None:
        with self._lock:
            entry = self._entries.setdefault(name, _Entry())
            if any(s.type_name == type_name for s in entry.servers):
                fut.set_result(None)
                return
            entry.waiters.append((type_name, fut))

    def remove_waiter(self, name: str, fut: asyncio.Future[None]) -> None:
        with self._lock:
            entry = self._entries.get(name)
            if entry is not None:
                entry.waiters = [(t, f) for t, f in entry.waiters if f is not fut]
                if not entry.servers and not entry.clients and not entry.waiters:
                    del self._entries[name]

    def snapshot(self) -> list[tuple[str, list[Service], list[Client]]]:
        with self._lock:
            return [
                (name, list(e.servers), list(e.clients))
                for name, e in sorted(self._entries.items())
                if e.servers or e.clients
            ]
