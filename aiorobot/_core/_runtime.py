"""``Runtime``: owns the bus, the clock, the loops and the pools; runs nodes; shuts down cleanly."""

from __future__ import annotations

import asyncio
import logging
import os
import re
import signal
import sys
import threading
import time
from collections.abc import Callable, Coroutine
from typing import TYPE_CHECKING, Any, TypeVar

from ._bus import Bus, Incompatibility
from ._errors import QoSIncompatibleError
from ._clock import Clock
from ._culprit import LateWatch
from ._graph import EndpointInfo, Graph, NodeInfo, ServiceInfo, TopicInfo
from ._handoff import raise_on
from ._node import Node
from ._priority import PriorityLoop
from ._pubsub import Publisher, Subscription, Tap
from ._qos import QoSProfile, ReliabilityPolicy
from ._time import ClockType, Time
from ._transport import MAX_DOMAIN_ID, Transport, make_transport
from ._waker import LoopWaker, TimerFdWaker, make_waker
from ._watchdog import Watchdog

if TYPE_CHECKING:
    import concurrent.futures

__all__ = ["ConfigLoader", "Runtime", "install_config_loader", "run"]

_log = logging.getLogger("aiorobot.runtime")
T = TypeVar("T")

EXECUTORS = ("main", "priority")
#: GIL switch interval while a priority loop runs: how long a GIL-holding thread may keep it
#: once the priority thread asks. Against a busy main thread, 50 us halved the 1 kHz timer's
#: lateness measured with 200 us (p50 324 -> 183 us, p99 710 -> 377 us) at no extra CPU.
PRIORITY_SWITCH_INTERVAL_SEC = 0.00005
#: Bounds for the shutdown sequence.
SHUTDOWN_TIMEOUT_SEC = 2.0
FLUSH_TIMEOUT_SEC = 1.0
#: How long a callback may hold a loop before the watchdog reports a stall.
STALL_THRESHOLD_SEC = 0.5
PRIORITY_STALL_THRESHOLD_SEC = 0.05
#: A priority-loop timer this late is a late period, whose culprit is looked for (``_culprit``).
LATE_THRESHOLD_SEC = 0.001

#: What ``Runtime(config=...)`` calls with its ``config``: returns the keyword arguments of
#: :class:`Runtime` that the file sets, and the builder of its nodes (``[(node, executor), ...]``,
#: called on entry, before anything starts). The core reads no config file: aiorobot.launch
#: installs this (``aiorobot.launch.open_runtime`` is the call for new code).
ConfigLoader = Callable[[Any], "tuple[dict[str, Any], Callable[[], list[tuple[Node, str]]]]"]
_config_loader: ConfigLoader | None = None


def install_config_loader(loader: ConfigLoader) -> None:
    """Make ``Runtime(config=...)`` read its file with ``loader`` (aiorobot.launch installs its own)."""
    global _config_loader
    _config_loader = loader


class Runtime:
    """Runs nodes: ``async with Runtime() as rt: rt.add_node(node); await rt.spin()``.

    Parameters
    ----------
    transport
        A registered transport name (``"local"``: one process; ``"zenoh"``) or a
        :class:`~aiorobot._core._transport.Transport`.
    domain_id
        Separates graphs on a shared network (as ``ROS_DOMAIN_ID``).
    use_sim_time
        Every clock follows ``/clock`` (``rosgraph_msgs/msg/Clock``); timers fire on it.
    strict_qos
        Raise :class:`QoSIncompatibleError` instead of warning when endpoints do not connect.
    config
        A config file path (``aiorobot run`` format) or a loaded ``GraphConfig``, read by
        aiorobot.launch (see ``aiorobot.launch.open_runtime``): its runtime settings replace
        the arguments above and its nodes are built, validated and added on entry.
    process_workers, thread_workers
        Sizes of the pools behind ``Node.offload`` and ``Node.run_in_thread``.
    priority_realtime
        Run the priority loop under ``SCHED_FIFO`` when the OS permits it (other
        processes then cannot delay it).

    handle_signals
        While ``spin`` runs, SIGINT and SIGTERM shut the runtime down cleanly.
    debug_messages
        Check the zero-copy contract: log an error when a publisher changes a message after
        publishing it, or a subscription callback changes the message it received
        (development aid; it pickles every message); and, while this runtime runs, check
        every assignment to a message field for type and range as rclpy's generated
        setters do (``msg.data = 'five'`` on an Int32 raises TypeError naming the field).
    shutdown_timeout
        Seconds the orderly shutdown (``on_shutdown`` hooks, stopping nodes and loops) may
        take. After a SIGINT/SIGTERM, once it has passed (or on a second signal), what is
        still blocked is named on stderr and the process exits with status 124.
    stall_threshold, priority_stall_threshold
        Seconds a callback may hold the main / priority loop before the watchdog reports
        the stall (once per callback, with its stack) and counts it in :meth:`statistics`.
    late_threshold
        Seconds after its deadline a priority-loop timer's callback may start before the
        period counts as late; the runtime then records what held the loop (a callback on
        it, or the function that held the GIL in another thread), reported by
        :meth:`statistics` (``"culprits"``), ``aiorobot top`` and the run summary. ``None``
        turns this watch off.
    """

    def __init__(
        self,
        *,
        transport: str | Transport = "local",
        domain_id: int = 0,
        use_sim_time: bool = False,
        strict_qos: bool = False,
        config: Any = None,
        process_workers: int | None = None,
        thread_workers: int | None = None,
        priority_realtime: bool = False,
        handle_signals: bool = True,
        debug_messages: bool = False,
        shutdown_timeout: float = SHUTDOWN_TIMEOUT_SEC,
        stall_threshold: float = STALL_THRESHOLD_SEC,
        priority_stall_threshold: float = PRIORITY_STALL_THRESHOLD_SEC,
        late_threshold: float | None = LATE_THRESHOLD_SEC,
    ) -> None:
        #: builds the config file's nodes on entry (``config=``)
        self._config_nodes: Callable[[], list[tuple[Node, str]]] | None = None
        if config is not None:
            if _config_loader is None:
                raise TypeError(
                    "Runtime(config=...): reading a graph file needs aiorobot.launch, which is not imported; "
                    "use aiorobot.launch.open_runtime(config) (or import aiorobot.launch first)"
                )
            settings, self._config_nodes = _config_loader(config)
            transport = settings["transport"]
            domain_id = settings["domain_id"]
            use_sim_time = settings["use_sim_time"]
            strict_qos = settings["strict_qos"]
            priority_realtime = settings["priority_realtime"]
            debug_messages = settings["debug_messages"]
            shutdown_timeout = settings["shutdown_timeout"]
            stall_threshold = settings["stall_threshold"]
            priority_stall_threshold = settings["priority_stall_threshold"]
            late_threshold = settings["late_threshold"]
        for name, value in (
            ("shutdown_timeout", shutdown_timeout),
            ("stall_threshold", stall_threshold),
            ("priority_stall_threshold", priority_stall_threshold),
            ("late_threshold", LATE_THRESHOLD_SEC if late_threshold is None else late_threshold),
        ):
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not value > 0:
                raise ValueError(f"{name}: expected a number of seconds > 0, found {value!r}")
        self.shutdown_timeout = float(shutdown_timeout)
        self._stall_thresholds = {"main": float(stall_threshold), "priority": float(priority_stall_threshold)}
        #: None: late periods are not watched (no sampling thread)
        self.late_threshold = None if late_threshold is None else float(late_threshold)
        self._late_watch: LateWatch | None = None
        self._watchdog = Watchdog()
        self._saved_handlers: dict[int, Any] = {}
        #: what the shutdown had to leave running (a blocked loop thread), one line each
        self.abandoned: list[str] = []
        #: callback failures per (node, entity): count (the first is logged with its traceback)
        self._failures: dict[tuple[str, str], int] = {}
        self._failure_logged: dict[tuple[str, str], float] = {}
        #: nodes whose on_start raised
        self._failed_starts: list[str] = []
        if isinstance(domain_id, bool) or not isinstance(domain_id, int) or not 0 <= domain_id <= MAX_DOMAIN_ID:
            raise ValueError(f"domain_id: expected an int in 0..{MAX_DOMAIN_ID}, found {domain_id!r}")
        self.transport = (
            transport if isinstance(transport, Transport) else make_transport(transport, domain_id=domain_id)
        )
        self.domain_id = domain_id
        self.use_sim_time = use_sim_time
        self.clock = Clock(ClockType.ROS_TIME, use_sim_time=use_sim_time)
        self._bus = Bus(strict_qos=strict_qos, debug_messages=debug_messages)
        self._assignment_checks = False  # enable_assignment_checks() is ours to undo
        self._bus.transport = self.transport
        self._nodes: list[Node] = []
        self._pending: list[tuple[Node, str]] = []
        self._stopping: list[Any] = []
        self._loop: asyncio.AbstractEventLoop | None = None
        self._thread_id: int | None = None
        self._waker: LoopWaker | TimerFdWaker | None = None
        self._priority: PriorityLoop | None = None
        self._priority_realtime = priority_realtime

        self._process_workers = process_workers
        self._thread_workers = thread_workers
        self._processes: concurrent.futures.ProcessPoolExecutor | None = None
        self._threads: concurrent.futures.ThreadPoolExecutor | None = None
        self._shutdown_event: asyncio.Event | None = None
        self._handle_signals = handle_signals
        self._clock_tap: Tap | None = None
        self._saved_switch_interval: float | None = None
        self._state = "new"  # new -> running -> closing -> closed

    def __repr__(self) -> str:
        return (
            f"<Runtime {self._state} transport={self.transport.name} nodes={len(self._nodes)}"
            f"{' sim_time' if self.use_sim_time else ''}>"
        )

    @property
    def strict_qos(self) -> bool:
        return self._bus.strict_qos

    @property
    def nodes(self) -> tuple[Node, ...]:
        return tuple(self._nodes)

    def now(self) -> Time:
        return self.clock.now()

    # -- context --------------------------------------------------------------------

    async def __aenter__(self) -> Runtime:
        if self._state != "new":
            raise RuntimeError(f"{self!r} cannot be entered twice")
        # a config file's nodes: validate everything before anything starts
        built = self._config_nodes() if self._config_nodes is not None else []
        self._loop = asyncio.get_running_loop()
        self._thread_id = threading.get_ident()
        self._waker = make_waker(self._loop, precise=True)
        self._shutdown_event = asyncio.Event()
        self._watchdog.watch("main", self._loop, self._thread_id, self._stall_thresholds["main"])
        try:
            await self.transport.open(self._bus)
        except BaseException:  # a refused session or a bad config: leave nothing started behind
            self._watchdog.unwatch(self._loop)
            self._watchdog.close()
            self._waker.close()
            self._waker = None
            raise
        if self.use_sim_time:
            from ..msgs.rosgraph_msgs import Clock as ClockMsg

            self._clock_tap = Tap(
                ClockMsg,
                "/clock",
                QoSProfile(reliability=ReliabilityPolicy.BEST_EFFORT, depth=1),
                self._on_clock,
                owner="<runtime clock>",
            )
            # the runtime's time source follows /clock from other processes too (a simulator, `bag play
            # --clock`), not only when one of its nodes happens to subscribe to /clock itself
            self._clock_tap.wants_remote = True
            self._bus.add_subscription(self._clock_tap)
        self._state = "running"
        if self._bus.debug_messages:
            from ..msgs._classgen import enable_assignment_checks

            enable_assignment_checks()  # message field assignments are type and range checked
            self._assignment_checks = True
        try:
            self.add_nodes([*self._pending, *built])
        except BaseException:
            await self._close()
            raise
        self._pending.clear()
        return self

    async def __aexit__(self, *exc: object) -> None:
        await self._close()

    def _on_clock(self, msg: Any) -> None:
        self.clock.set_sim_time(int(msg.clock.sec) * 1_000_000_000 + int(msg.clock.nanosec))

    # -- nodes ------------------------------------------------------------------------

    def add_node(self, node: Node, executor: str = "main") -> Node:
        """Add ``node`` on the main loop or the priority loop and start it."""
        if not isinstance(node, Node):
            raise TypeError(f"add_node expects an aiorobot.Node, got {node!r}")
        if executor not in EXECUTORS:
            raise ValueError(f"executor: expected 'main' or 'priority', found {executor!r}")
        if node._runtime is not None or any(n is node for n, _ in self._pending):
            raise ValueError(f"{node!r} is already added to a runtime")
        fqn = node.get_fully_qualified_name()
        taken = [n.get_fully_qualified_name() for n in self._nodes] + [
            n.get_fully_qualified_name() for n, _ in self._pending
        ]
        if fqn in taken:
            raise ValueError(f"a node named {fqn} is already in this runtime; node names must be unique")
        if self._state == "new":
            self._pending.append((node, executor))
            return node
        if self._state != "running":
            raise RuntimeError(f"cannot add {node!r}: the runtime is {self._state}")
        if executor == "priority":
            prio = self._priority_loop()
            assert prio.loop is not None and prio.thread_id is not None and prio.waker is not None
            node._bind(self, executor, prio.loop, prio.thread_id, prio.waker)
        else:
            assert self._loop is not None and self._thread_id is not None and self._waker is not None
            node._bind(self, executor, self._loop, self._thread_id, self._waker)
        added: list[Any] = []
        self.transport.node_added(node)
        try:
            node.on_added()
            for entity in (*node._publishers, *node._subscriptions, *node._services, *node._clients):
                self._bus_add(entity)
                added.append(entity)
        except BaseException:
            for entity in added:
                self._bus_remove(entity)
            self.transport.node_removed(node)
            node._unbind()
            raise
        self._nodes.append(node)
        node._call_soon(node._start)
        return node

    def check_qos(self, nodes: list[Node]) -> list[Incompatibility]:
        """What would not connect if ``nodes`` joined this runtime (nothing is added).

        ``add_nodes`` uses it under ``strict_qos`` so that a graph that cannot connect
        is refused whole, before any of its nodes starts.
        """
        pubs = [p for n in nodes for p in n._publishers]
        subs = [s for n in nodes for s in n._subscriptions]
        return [self._bus.incompatibility(p, s, reason) for p, s, reason in self._bus.preview(pubs, subs)]

    def _bus_add(self, entity: Any) -> None:
        """Put a node's publisher, subscription, service or client on the bus (matched with its
        peers, announced through the transport)."""
        if isinstance(entity, Publisher):
            self._bus.add_publisher(entity)
        elif isinstance(entity, Subscription):
            self._bus.add_subscription(entity)
        else:
            self._bus.services.add(entity)

    def _bus_remove(self, entity: Any) -> None:
        """Take what :meth:`_bus_add` put on the bus off it again."""
        if isinstance(entity, (Publisher, Subscription)):
            self._bus.remove(entity)
        else:
            self._bus.services.remove(entity)

    def add_nodes(self, nodes: list[tuple[Node, str]]) -> None:
        """Add several ``(node, executor)`` pairs; under ``strict_qos`` all or none."""
        if self.strict_qos:
            problems = self.check_qos([node for node, _ in nodes])
            if problems:
                raise QoSIncompatibleError(str(problems[0]))
        for node, executor in nodes:
            self.add_node(node, executor=executor)

    def remove_node(self, node: Node) -> None:
        """Stop ``node``: its endpoints leave the graph at once, its tasks end on its loop."""
        if node not in self._nodes:
            raise ValueError(f"{node!r} is not in this runtime")
        self._nodes.remove(node)
        self._detach_node(node)

    def _detach_node(self, node: Node) -> None:
        for entity in (*node._publishers, *node._subscriptions, *node._services, *node._clients):
            self._bus_remove(entity)
        self.transport.node_removed(node)
        loop = node._loop
        if loop is not None and not loop.is_closed():
            if loop is self._loop:
                self._stopping.append(asyncio.ensure_future(node._stop(), loop=loop))
            else:
                self._stopping.append(asyncio.run_coroutine_threadsafe(node._stop(), loop))
        node._unbind()

    def _priority_loop(self) -> PriorityLoop:
        if self._priority is None:
            prio = PriorityLoop(realtime=self._priority_realtime)
            prio.on_escape = self._escaped_priority_loop
            prio.start()
            self._priority = prio
            assert prio.loop is not None and prio.thread_id is not None
            self._watchdog.watch("priority", prio.loop, prio.thread_id, self._stall_thresholds["priority"])
            self._saved_switch_interval = sys.getswitchinterval()
            sys.setswitchinterval(min(self._saved_switch_interval, PRIORITY_SWITCH_INTERVAL_SEC))
            if self.late_threshold is not None:
                loops = {self._thread_id: "main"} if self._thread_id is not None else {}
                self._late_watch = LateWatch(
                    self.late_threshold, prio.thread_id, loops=loops, recent=self._recent_callback
                )
        return self._priority

    def _escaped_priority_loop(self, exc: BaseException) -> None:
        """On the priority thread: a task there raised SystemExit or KeyboardInterrupt, which
        asyncio lets out of the loop. Raised on the main loop instead, as if one of its tasks had
        (the program ends as asyncio ends it); the priority loop runs on until shutdown."""
        if self._loop is not None:
            raise_on(self._loop, exc)

    @property
    def priority_loop(self) -> PriorityLoop | None:
        return self._priority

    def _recent_callback(self, executor: str, since_ns: int) -> tuple[Node, Any, int] | None:
        """The node callback on ``executor``'s loop that ran longest since ``since_ns``: (node, entity, ns)."""
        best: tuple[Node, Any, int] | None = None
        now = time.monotonic_ns()
        for node in list(self._nodes):
            last = node._last_callback
            if last is None or node._executor != executor:
                continue
            ran = min(last[1], now) - max(last[0], since_ns)
            if ran > 0 and (best is None or ran > best[2]):
                best = (node, last[2], ran)
        return best

    @property
    def late_watch(self) -> LateWatch | None:
        """What finds the culprits of late priority periods; None until a node runs on that loop."""
        return self._late_watch

    # -- running ------------------------------------------------------------------------

    async def spin(self, duration_sec: float | None = None) -> None:
        """Run until :meth:`shutdown` (or SIGINT/SIGTERM), or for ``duration_sec`` of wall time."""
        if self._state != "running" or self._shutdown_event is None:
            raise RuntimeError(f"spin needs an entered runtime: use `async with Runtime() as rt` ({self!r})")
        if duration_sec is not None and (isinstance(duration_sec, bool) or not duration_sec >= 0):
            raise ValueError(f"spin duration_sec: expected a number >= 0 or None, got {duration_sec!r}")
        self._install_signal_handlers()
        if duration_sec is None:
            await self._shutdown_event.wait()
        else:
            try:
                await asyncio.wait_for(self._shutdown_event.wait(), duration_sec)
            except TimeoutError:
                pass

    def _install_signal_handlers(self) -> None:
        """Python-level handlers, kept until the runtime has closed.

        They run even while a callback blocks the main thread (a ``time.sleep`` is
        interrupted for them), unlike ``loop.add_signal_handler``.
        """
        if self._saved_handlers or not self._handle_signals:
            return
        if threading.current_thread() is not threading.main_thread():
            return
        for sig in (signal.SIGINT, signal.SIGTERM):
            try:
                self._saved_handlers[sig] = signal.signal(sig, self._on_signal_handler)
            except (ValueError, OSError):  # pragma: no cover - not the main thread of the main interpreter
                pass

    def _restore_signal_handlers(self) -> None:
        for sig, previous in self._saved_handlers.items():
            signal.signal(sig, previous if previous is not None else signal.SIG_DFL)
        self._saved_handlers.clear()

    def _on_signal_handler(self, signum: int, frame: Any) -> None:
        # Runs between two bytecodes of the main thread: no logging, no locks here.
        count = self._watchdog.on_signal(signal.Signals(signum).name, self.shutdown_timeout)
        loop = self._loop
        if count == 1 and loop is not None and not loop.is_closed():
            loop.call_soon_threadsafe(self._on_signal, signum)

    def _on_signal(self, sig: int) -> None:
        _log.info(
            f"{signal.Signals(sig).name} received: shutting down (within {self.shutdown_timeout:g} s; "
            "a second Ctrl-C abandons what is blocked)"
        )
        self.shutdown()

    def _record_failure(self, node: str, entity: str) -> tuple[int, bool]:
        """Count one failure of ``entity`` in ``node``: (how many so far, whether to log it now)."""
        from ._node import FAILURE_LOG_PERIOD_SEC

        key = (node, entity)
        count = self._failures.get(key, 0) + 1
        self._failures[key] = count
        now = time.monotonic()
        last = self._failure_logged.get(key)
        if last is None or now - last >= FAILURE_LOG_PERIOD_SEC:
            self._failure_logged[key] = now
            return count, True
        return count, False

    def _record_failed_start(self, node: Node, err: BaseException) -> None:
        fqn = node.get_fully_qualified_name()
        self._failed_starts.append(fqn)
        policy = getattr(node, "_on_failure", "stop")
        if policy == "stop":
            _log.error(f"{fqn} failed to start ({type(err).__name__}: {err}); stopping the run")
            self.shutdown()

    def statistics(self) -> dict[str, Any]:
        """Counts of what went wrong: stalls, callback failures, failed starts, late periods.

        ``{"stalls": {(loop, node, entity): n}, "failures": {(node, entity): n},
        "failed_starts": [node, ...], "late_periods": n, "culprits": [Culprit, ...]}``; the
        culprits of late priority periods come most lateness first (see ``late_threshold``).
        """
        watch = self._late_watch
        return {
            "stalls": dict(self._watchdog.stalls),
            "failures": dict(self._failures),
            "failed_starts": list(self._failed_starts),
            "late_periods": watch.late_periods if watch is not None else 0,
            "culprits": watch.culprits() if watch is not None else [],
        }

    async def settle(self, *, rounds: int = 3, max_rounds: int = 1000) -> None:
        """Run the main and priority loops until every subscription and service queue is handled.

        Waits for ``rounds`` consecutive quiet passes (a pass yields to the main loop and makes
        a round trip through the priority loop), at most ``max_rounds`` passes. Callbacks
        waiting on I/O or on time may still be pending afterwards: wait for their effects.
        """
        quiet = 0
        for _ in range(max_rounds):
            await asyncio.sleep(0)
            prio = self._priority
            if prio is not None and prio.loop is not None:
                await prio.run(asyncio.sleep(0))
            if all(node._idle() for node in self._nodes):
                quiet += 1
                if quiet >= rounds:
                    return
            else:
                quiet = 0

    def shutdown(self) -> None:
        """Ask ``spin`` to return (from any thread). ``async with`` then stops everything."""
        event, loop = self._shutdown_event, self._loop
        if event is None or loop is None:
            return
        if threading.get_ident() == self._thread_id:
            event.set()
        elif not loop.is_closed():
            loop.call_soon_threadsafe(event.set)

    @property
    def is_shutdown(self) -> bool:
        return self._state in ("closing", "closed") or (
            self._shutdown_event is not None and self._shutdown_event.is_set()
        )

    # -- shutdown -----------------------------------------------------------------------

    async def _on_loop(self, node: Node, coro: Coroutine[Any, Any, T]) -> T:
        if node._loop is self._loop or node._loop is None:
            return await coro
        assert self._priority is not None
        return await self._priority.run(coro)

    async def _close(self) -> None:
        if self._state in ("closing", "closed"):
            return
        self._state = "closing"
        if self._assignment_checks:
            from ..msgs._classgen import disable_assignment_checks

            disable_assignment_checks()
            self._assignment_checks = False
        loop = asyncio.get_running_loop()
        deadline = loop.time() + self.shutdown_timeout

        def remaining() -> float:
            return max(0.0, deadline - loop.time())

        nodes = list(self._nodes)
        # 1. on_shutdown hooks, each on its node's loop (controllers send their last command here).
        if nodes:
            # Scheduled after each node's _start on the same loop, so every hook sees a started node.
            hooks = [
                asyncio.ensure_future(self._on_loop(n, n._run_hook(n.on_shutdown, "on_shutdown"))) for n in nodes
            ]
            done, pending = await asyncio.wait(hooks, timeout=remaining())
            for task in pending:
                task.cancel()
            if pending:
                late = [n.get_fully_qualified_name() for n, h in zip(nodes, hooks) if h in pending]
                _log.warning(f"on_shutdown of {', '.join(late)} did not finish within shutdown_timeout; cancelled")
                await asyncio.wait(pending, timeout=0.1)
            # 2. Let what the hooks published reach its subscribers.
            await self._flush(nodes, min(FLUSH_TIMEOUT_SEC, remaining()))
        # 3. Stop every node.
        for node in nodes:
            self._nodes.remove(node)
            self._detach_node(node)
        if self._stopping:
            stopping = [f if isinstance(f, asyncio.Future) else asyncio.wrap_future(f) for f in self._stopping]
            _, late_stops = await asyncio.wait(stopping, timeout=max(remaining(), 0.05))
            for f in late_stops:
                f.cancel()
            self._stopping.clear()
        if self._clock_tap is not None:
            self._bus.remove(self._clock_tap)
            self._clock_tap = None
        # 4. Loops, transport, pools.
        if self._priority is not None:
            prio = self._priority
            if prio.loop is not None:
                self._watchdog.unwatch(prio.loop)
            blocked = self._watchdog.describe_blocked()
            if not prio.stop(timeout=max(remaining(), 0.05)):
                what = [b for b in blocked if b.startswith("priority")] or ["priority loop: blocked"]
                self.abandoned.extend(what)
                _log.error(f"the priority loop did not stop within shutdown_timeout; abandoned: {'; '.join(what)}")
            self._priority = None
            if self._late_watch is not None:
                self._late_watch.close()  # its figures stay readable through statistics()
            if self._saved_switch_interval is not None:
                sys.setswitchinterval(self._saved_switch_interval)
        await self.transport.close()
        if self._processes is not None:
            self._processes.shutdown(wait=not self.abandoned, cancel_futures=True)
            self._processes = None
        if self._threads is not None:
            self._threads.shutdown(wait=not self.abandoned, cancel_futures=True)
            self._threads = None
        if self._waker is not None:
            self._waker.close()
            self._waker = None
        self._restore_signal_handlers()
        if not self.abandoned:
            self._watchdog.finished()  # disarm the deadline; with something abandoned it still fires
        self._state = "closed"

    async def _flush(self, nodes: list[Node], timeout_sec: float = FLUSH_TIMEOUT_SEC) -> None:
        """Wait (bounded) until every subscription has handled what is queued for it."""
        loop = asyncio.get_running_loop()
        deadline = loop.time() + timeout_sec
        quiet_rounds = 0
        while loop.time() < deadline:
            await asyncio.sleep(0)
            if self._priority is not None and self._priority.loop is not None:
                # A round trip through the priority loop drains its call_soon_threadsafe queue.
                try:
                    await asyncio.wait_for(self._priority.run(asyncio.sleep(0)), max(0.0, deadline - loop.time()))
                except TimeoutError:
                    return
            if all(n._idle() for n in nodes):
                quiet_rounds += 1
                if quiet_rounds >= 2:
                    return
            else:
                quiet_rounds = 0
                await asyncio.sleep(0.001)

    # -- pools ----------------------------------------------------------------------------

    def _process_pool(self) -> concurrent.futures.ProcessPoolExecutor:
        if self._state != "running":
            raise RuntimeError(f"offload needs a running runtime ({self!r})")
        if self._processes is None:
            import concurrent.futures
            import multiprocessing

            _check_main_guard()

            method = "forkserver" if "forkserver" in multiprocessing.get_all_start_methods() else "spawn"
            self._processes = concurrent.futures.ProcessPoolExecutor(
                max_workers=self._process_workers or os.cpu_count() or 2,
                mp_context=multiprocessing.get_context(method),
            )
        return self._processes

    def _thread_pool(self) -> concurrent.futures.ThreadPoolExecutor:
        if self._state != "running":
            raise RuntimeError(f"run_in_thread needs a running runtime ({self!r})")
        if self._threads is None:
            import concurrent.futures

            self._threads = concurrent.futures.ThreadPoolExecutor(
                max_workers=self._thread_workers or min(32, (os.cpu_count() or 2) + 4),
                thread_name_prefix="aiorobot-worker",
            )
        return self._threads

    # -- introspection ------------------------------------------------------------------

    @property
    def graph(self) -> Graph:
        """A snapshot of nodes, topics (types and QoS of every endpoint) and QoS incompatibilities."""
        nodes = tuple(
            NodeInfo(n.get_name(), n.get_namespace(), n.get_fully_qualified_name(), n.executor or "")
            for n in self._nodes
        ) + tuple(self.transport.remote_nodes())
        topics = []
        for t in self._bus.snapshot():
            def info(e: Any, kind: str, topic: str = t.name) -> EndpointInfo:
                return EndpointInfo(e.node_name, topic, e.type_name, kind, e.qos)

            pubs = tuple(info(p, "publisher") for p in t.publishers)
            subs = tuple(info(s, "subscription") for s in t.subscriptions)
            types = tuple(sorted({e.type for e in (*pubs, *subs)}))
            topics.append(TopicInfo(t.name, types, pubs, subs))
        services = tuple(
            ServiceInfo(
                name,
                tuple(sorted({e.type_name for e in (*servers, *clients)})),
                tuple(s.node_name for s in servers),
                tuple(c.node_name for c in clients),
            )
            for name, servers, clients in self._bus.services.snapshot()
        )
        suffix = "/_action/send_goal"
        actions = tuple(
            ServiceInfo(s.name[: -len(suffix)], tuple(t.rsplit("_SendGoal", 1)[0] for t in s.types), s.servers, s.clients)
            for s in services
            if s.name.endswith(suffix)
        )
        return Graph(nodes, tuple(topics), tuple(self._bus.incompatibilities()), services, actions)


_MAIN_GUARD = re.compile(r"""__name__\s*==\s*['"]__main__['"]""")


def _check_main_guard() -> None:
    """Process workers import the main script: without the guard it would run again in each."""
    main = sys.modules.get("__main__")
    path = getattr(main, "__file__", None)
    if main is None or path is None or getattr(main, "__spec__", None) is not None:
        return  # interactive, ``python -m``, or a console script: nothing to re-run
    try:
        with open(path, encoding="utf-8") as f:
            source = f.read()
    except (OSError, UnicodeDecodeError):
        return
    if not _MAIN_GUARD.search(source):
        raise RuntimeError(
            f"offload starts worker processes that import {os.path.basename(path)}: put its entry point "
            f'under `if __name__ == "__main__":` (e.g. `if __name__ == "__main__": aiorobot.run(main())`)'
        )


def run(main: Coroutine[Any, Any, T], *, debug: bool | None = None) -> T:
    """Run ``main`` to completion on a uvloop event loop (``asyncio.run`` elsewhere)."""
    try:
        import uvloop
    except ImportError:  # pragma: no cover
        return asyncio.run(main, debug=debug)
    with asyncio.Runner(loop_factory=uvloop.new_event_loop, debug=debug) as runner:
        return runner.run(main)



