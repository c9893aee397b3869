"""``aiorobot.lowlevel``: the seam for code that extends aiorobot rather than uses it.

A recorder, a bridge, a simulator, a motor controller or a compatibility layer needs a few
things a node does not: to see every message of a topic without being a subscriber, to learn
of publishers as they appear, to act on Ctrl-C before any loop gets a turn, to hand a thread
the runtime's loop. These functions give exactly that, and are kept stable as the core
changes; the core's private members (``runtime._bus``, ``node._loop``, ...) are not. (trio's
``trio.lowlevel`` is the model: a documented door beside the front one.)

What an ordinary node needs stays on the front door: ``Node.create_task`` (a task the node
owns), ``Runtime.settle`` (let both loops catch up), ``Runtime.graph``.

- **Taps and graph watching** — :class:`Tap`, :func:`add_tap`, :func:`remove_tap`,
  :func:`watch_publishers`: a tap is called with every message of its topic in the
  publishing thread (no queue, no loop hop), as a recorder or a bridge wants.
- **Emergency stops** — :func:`add_emergency_stop`, :func:`remove_emergency_stop`.
- **Loops and threads** — :func:`node_loop`, :func:`wait_until_ns`, :func:`run_callback`,
  :func:`adopt_thread`, :func:`stop_watching_stalls`.
- **Entities built elsewhere** — :func:`add_client` (a client of an extension's own class),
  :func:`set_on_failure` (the ``on_failure`` policy of a node a launcher built).
- **Messages** — :func:`wait_for_message` (``aiorobot.testing`` re-exports it).

This module belongs to the core: it may read the core's private state, extensions may not.
"""

from __future__ import annotations

import asyncio
import threading
from collections.abc import Callable
from typing import Any, TypeVar

from . import CallbackGroup, Client, Node, Publisher, QoSProfile, Runtime
from ._core._pubsub import Endpoint, Tap

__all__ = [
    "ON_FAILURE",
    "Tap",
    "add_client",
    "add_emergency_stop",
    "add_tap",
    "adopt_thread",
    "node_loop",
    "remove_emergency_stop",
    "remove_tap",
    "run_callback",
    "set_on_failure",
    "stop_watching_stalls",
    "wait_for_message",
    "wait_until_ns",
    "watch_publishers",
]

M = TypeVar("M")

#: what a node's failed ``on_start`` does to the run: stop it, go on, or retry ``on_start``
ON_FAILURE = ("stop", "continue", "restart")


# -- taps and graph watching ------------------------------------------------------------------


def add_tap(runtime: Runtime, tap: Tap) -> None:
    """Connect ``tap`` to the publishers of its topic in ``runtime`` (and, with
    ``tap.wants_remote = True``, to remote ones over the transport). QoS is matched as for a
    subscription; a transient-local tap receives the publishers' history at once."""
    runtime._bus.add_subscription(tap)


def remove_tap(runtime: Runtime, tap: Tap) -> None:
    """Disconnect ``tap``; removing one that is not connected does nothing."""
    runtime._bus.remove(tap)


def watch_publishers(
    runtime: Runtime, callback: Callable[[Publisher[Any]], None], *, existing: bool = True
) -> Callable[[], None]:
    """Call ``callback(publisher)`` for every publisher that joins ``runtime`` from now on (and,
    with ``existing``, first for each one already there). Returns the function that stops watching.

    A joining publisher is reported in the thread that adds it, before the adding call returns,
    so a tap added from the callback sees the publisher's first message. A publisher joining
    while this call runs may be reported twice: key what the callback builds by topic.
    """

    def on_endpoint(endpoint: Endpoint) -> None:
        if isinstance(endpoint, Publisher):
            callback(endpoint)

    unwatch = runtime._bus.watch(on_endpoint)
    if existing:
        for topic in runtime._bus.snapshot():
            for pub in topic.publishers:
                callback(pub)
    return unwatch


# -- emergency stops --------------------------------------------------------------------------


def add_emergency_stop(runtime: Runtime, owner: str, fn: Callable[[], Any]) -> None:
    """On SIGINT/SIGTERM, call ``fn()`` from the runtime's watchdog thread before anything else.

    No callback blocking a loop can delay it: a motor controller writes its zero command here.
    ``fn`` must be thread-safe and quick; what it raises is logged under ``owner``.
    """
    runtime._watchdog.add_emergency_stop(owner, fn)


def remove_emergency_stop(runtime: Runtime, fn: Callable[[], Any]) -> None:
    """Forget ``fn`` (added with :func:`add_emergency_stop`); forgetting an unknown one does nothing."""
    runtime._watchdog.remove_emergency_stop(fn)


# -- loops and threads ------------------------------------------------------------------------


def node_loop(node: Node) -> asyncio.AbstractEventLoop | None:
    """The event loop ``node`` runs on (the main or the priority loop); ``None`` until it is added.

    For code in other threads: ``asyncio.run_coroutine_threadsafe(coro, node_loop(node))``.
    """
    return node._loop


async def wait_until_ns(node: Node, deadline_ns: int) -> None:
    """Sleep until ``time.monotonic_ns()`` reaches ``deadline_ns``, with the node loop's precise
    waker (asyncio's timers on uvloop are whole milliseconds). Call it on the node's loop."""
    waker = node._waker
    if waker is None:
        raise RuntimeError(f"wait_until_ns: {node!r} is not added to a runtime")
    await waker.wait_until_ns(deadline_ns)


async def run_callback(node: Node, entity: Any, group: CallbackGroup, fn: Callable[..., Any], *args: Any) -> Any:
    """Run ``fn(*args)`` (sync or async) as the node runs its own callbacks: under ``group``,
    with what it raises logged and counted against ``entity`` (the node goes on; returns ``None``)."""
    return await node._invoke(entity, group, fn, *args)


def adopt_thread(runtime: Runtime) -> None:
    """Make the calling thread the one that runs ``runtime``'s main loop.

    The core takes the direct path (no ``call_soon_threadsafe``) when the caller's thread is
    the loop's, and remembers that thread on entry. A runtime whose loop different threads
    run in turn (rclpy's executors spin from whichever thread calls ``spin``) calls this from
    the thread about to run the loop, while no other thread runs it.
    """
    tid = threading.get_ident()
    if runtime._thread_id == tid:
        return
    runtime._thread_id = tid
    for node in runtime._nodes:
        if node._loop is runtime._loop:
            node._thread_id = tid
            for pub in node._publishers:
                pub._thread_id = tid


def stop_watching_stalls(runtime: Runtime) -> None:
    """Stop reporting stalls of ``runtime``'s main loop: for a loop that only runs while some
    thread spins it (each pause between spins would be reported as a stall)."""
    if runtime._loop is not None:
        runtime._watchdog.unwatch(runtime._loop)


# -- entities built elsewhere -----------------------------------------------------------------


def add_client(node: Node, client: Client) -> Client:
    """Make ``client`` (built by an extension, e.g. of its own ``Client`` subclass, for ``node``)
    one of ``node``'s: listed in ``node.clients``, registered with the runtime, destroyed with it."""
    if client.node is not node:
        raise ValueError(f"add_client: {client!r} was built for {client.node!r}, not {node!r}")
    node._clients.append(client)
    if node._runtime is not None:
        node._runtime._bus.services.add(client)
    return client


def set_on_failure(node: Node, policy: str) -> None:
    """What a failure of ``node``'s ``on_start`` does to the run (``[[nodes]] on_failure`` of a
    config file): ``"stop"`` it (the default), ``"continue"``, or ``"restart"`` ``on_start``."""
    if policy not in ON_FAILURE:
        raise ValueError(f"on_failure: expected one of {', '.join(ON_FAILURE)}, found {policy!r}")
    node._on_failure = policy  # type: ignore[attr-defined]


# -- messages ---------------------------------------------------------------------------------


async def wait_for_message(
    node: Node, msg_type: type[M], topic: str, timeout_sec: float = 5.0, *, qos: QoSProfile | int = 10
) -> M:
    """Return the next message on ``topic`` (as seen by ``node``); ``TimeoutError`` after ``timeout_sec``.

    ``node`` must run on the main loop (the loop the caller awaits on).
    """
    if node.executor != "main":
        raise ValueError(
            f"wait_for_message needs a node on the main loop, got {node!r}; add a helper node with executor='main'"
        )
    async with node.subscribe(msg_type, topic, qos) as stream:
        try:
            async with asyncio.timeout(timeout_sec):
                return await anext(stream)
        except TimeoutError:
            raise TimeoutError(
                f"no {getattr(msg_type, '__msgtype__', msg_type)} on {node.resolve_topic_name(topic)} "
                f"within {timeout_sec} s"
            ) from None
