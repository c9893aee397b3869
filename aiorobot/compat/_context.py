"""rclpy's context on aiorobot: one :class:`~aiorobot.Runtime` driven by whichever thread spins.

``rclpy.init`` builds an event loop and enters a runtime on it, without running it.
Spinning (``rclpy.spin``, ``spin_once``, ``spin_until_future_complete``, a blocking
``client.call``) runs that loop in the calling thread until its condition holds, so
plain-function callbacks run in the spinning thread as rclpy's SingleThreadedExecutor
runs them. Between spins nothing runs. SIGINT shuts the context down and raises
``KeyboardInterrupt`` in the main thread; SIGTERM shuts it down, so a spin raises
``ExternalShutdownException``; both as rclpy.
"""

from __future__ import annotations

import asyncio
import collections
import contextlib
import functools
import os
import signal
import sys
import threading
import time
import weakref
from collections.abc import Callable, Coroutine, Iterator
from typing import Any, TypeVar

from .._core._handoff import post, wake
from .._core._ros_args import RosArgs, parse_ros_args
from .._core._runtime import Runtime
from ..lowlevel import adopt_thread, stop_watching_stalls

__all__ = ["Context", "ExternalShutdownException", "default_context", "settings"]


class _Settings:
    """What ``aiorobot exec`` sets before the program runs: transport, extra native nodes."""

    transport: str = "local"
    #: ``module:Class`` of aiorobot nodes added to the runtime at ``rclpy.init`` (mixed graphs)
    nodes: list[str] = []


settings = _Settings()

T = TypeVar("T")


class ExternalShutdownException(Exception):
    """The context was shut down (by a signal, or another thread) while spinning (rclpy's)."""


class Context:
    """rclpy's ``Context``: ``init``, ``ok``, ``shutdown``, ``try_shutdown``, ``on_shutdown``."""

    def __init__(self) -> None:
        self.loop: asyncio.AbstractEventLoop | None = None
        self.runtime: Runtime | None = None
        self.argv: list[str] = []
        self.ros_args: RosArgs = RosArgs()
        self._ok = False
        self._closed = True
        self._lock = threading.RLock()
        self._spin_lock = threading.Lock()
        self._spin_thread: int | None = None
        self._waiter: asyncio.Future[None] | None = None
        self._local = threading.local()
        self._on_shutdown: list[Callable[[], Any]] = []
        self._saved_handlers: dict[int, Any] = {}
        self._saved_unraisablehook: Any = None
        #: Ctrl-C arrived while the loop ran in this thread: the spin raises KeyboardInterrupt on its way out
        self._interrupted = False
        #: ``sys.exit()`` in a callback: the spin in progress raises it on its way out
        self._exit: SystemExit | None = None
        #: spin loops (rclpy.spin, Executor.spin) running in the main thread: Ctrl-C between two
        #: passes is raised by the loop, not wherever the main thread happens to be
        self._main_spin_depth = 0
        #: the executor whose spin is running the loop (decides where plain callbacks run)
        self.executor: Any = None
        self.callbacks_done = 0
        #: callbacks the spin in progress may still start (spin_once: one); None: no limit
        self._admissions: int | None = None
        self._admit_waiters: collections.deque[tuple[asyncio.Future[Any], Any, Any]] = collections.deque()
        self._finished_waiters: list[asyncio.Future[None]] = []
        #: threads waiting while another executor spins in another thread (see _wait_beside)
        self._beside = threading.Condition()
        self._exit_hook = False

    def __repr__(self) -> str:
        return f"<rclpy Context {'ok' if self._ok else 'shut down'} (aiorobot)>"

    # -- rclpy's surface -----------------------------------------------------------

    def init(self, args: list[str] | None = None, *, domain_id: int | None = None) -> None:
        with self._lock:
            if self._ok or not self._closed:
                raise RuntimeError("rclpy.init: the context is already initialized; call rclpy.shutdown() first")
            argv = list(sys.argv if args is None else args)
            self.ros_args = parse_ros_args(argv)
            self.argv = argv
            if domain_id is None:
                domain_id = int(os.environ.get("ROS_DOMAIN_ID", "0") or 0)
            loop = asyncio.new_event_loop()
            runtime = Runtime(transport=settings.transport, domain_id=domain_id, handle_signals=False)
            _run(loop, runtime.__aenter__())
            for spec in settings.nodes:
                runtime.add_node(_build_node(spec))
            # The loop only runs while a thread spins, and rclpy callbacks may block: the
            # stall watchdog would report every pause between spins, so it is off here.
            stop_watching_stalls(runtime)
            self.loop, self.runtime = loop, runtime
            self._ok, self._closed = True, False
            self._install_signal_handlers()
            if not self._exit_hook:
                self._exit_hook = True
                try:  # before Python joins the non-daemon threads, as concurrent.futures registers its own
                    threading._register_atexit(functools.partial(_at_exit, weakref.ref(self)))  # type: ignore[attr-defined]
                except RuntimeError:  # pragma: no cover - init during interpreter shutdown
                    pass

    def ok(self) -> bool:
        return self._ok

    def shutdown(self) -> None:
        """Shut down; ``RuntimeError`` when already shut down (rclpy raises ``RCLError`` there)."""
        with self._lock:
            if not self._ok:
                raise RuntimeError(
                    "rclpy.shutdown: the context is already shut down (or was never initialized); "
                    "rclpy.try_shutdown() does nothing in that case"
                )
            self._request_shutdown()
        self._close_if_idle()

    def try_shutdown(self) -> None:
        with self._lock:
            if self._ok:
                self._request_shutdown()
        self._close_if_idle()

    def on_shutdown(self, callback: Callable[[], Any]) -> None:
        self._on_shutdown.append(callback)

    # -- running the loop ---------------------------------------------------------------

    @contextlib.contextmanager
    def spinning(self) -> Iterator[None]:
        """Around a spin loop: a Ctrl-C between its passes ends it with KeyboardInterrupt, as rclpy's.

        Without this the handler would raise wherever the main thread is between two passes
        (inside a weakref callback or a ``__del__``, where Python ignores it and the program
        runs on).
        """
        main = threading.current_thread() is threading.main_thread()
        if main:
            self._main_spin_depth += 1
        try:
            yield
        finally:
            if main:
                self._main_spin_depth -= 1
        self.raise_if_interrupted()

    def raise_if_interrupted(self) -> None:
        if self._interrupted and threading.current_thread() is threading.main_thread():
            self._interrupted = False
            self._close_if_idle()
            raise KeyboardInterrupt

    def exit_from_callback(self, exc: SystemExit) -> None:
        """``sys.exit()`` in a callback: the spin in progress ends and raises it, as rclpy's spin
        does, and the entity whose callback it was lives on for a later spin (the SystemExit
        does not end the aiorobot task that runs it)."""
        self._exit = exc
        self.wake()

    def in_callback(self) -> bool:
        return bool(getattr(self._local, "depth", 0))

    def call_as_callback(self, fn: Callable[..., T], *args: Any, **kwargs: Any) -> T:
        self._local.depth = getattr(self._local, "depth", 0) + 1
        try:
            return fn(*args, **kwargs)
        finally:
            self._local.depth -= 1

    async def admit(self, runner: Callable[[], Any] | None = None, owner: Any = None) -> Any:
        """Wait until the spin in progress may start one more callback.

        rclpy's ``spin_once`` executes one ready callback; a callback that becomes ready
        during it (a guard condition its callback triggers, the next message) waits here
        for the next spin, in the order it arrived. Under a custom executor's
        ``wait_for_ready_callbacks`` a waiting plain callback (``runner``) is handed out
        instead: the returned handler runs it wherever the executor calls it, and the
        caller awaits that handler.
        """
        while self._admissions == 0:
            waiter = asyncio.get_running_loop().create_future()
            entry = (waiter, runner, owner)
            self._admit_waiters.append(entry)
            if runner is not None:
                self.wake()  # a custom executor's wait_for_ready_callbacks may take it
            try:
                handler = await waiter
            finally:
                if entry in self._admit_waiters:
                    self._admit_waiters.remove(entry)
            if handler is not None:
                return handler
        if self._admissions is not None:
            self._admissions -= 1
        return None

    def _open_admissions(self, admissions: int | None) -> None:
        self._admissions = admissions
        waiters, self._admit_waiters = self._admit_waiters, collections.deque()
        for waiter, _runner, _owner in waiters:
            if not waiter.done():
                waiter.set_result(None)

    def ready_runners(self) -> list[tuple[asyncio.Future[Any], Callable[[], Any], Any]]:
        """Plain callbacks waiting to start that a custom executor may take."""
        return [(w, r, o) for w, r, o in self._admit_waiters if r is not None and not w.done()]

    def callback_finished(self) -> None:
        self.callbacks_done += 1
        waiters, self._finished_waiters = self._finished_waiters, []
        for waiter in waiters:
            if not waiter.done():
                post(waiter.get_loop(), wake, waiter)
        self.wake()

    async def next_callback_finished(self) -> None:
        """Until some callback of the program finishes (what may change a custom group's mind)."""
        waiter = asyncio.get_running_loop().create_future()
        self._finished_waiters.append(waiter)
        await waiter

    def wake(self) -> None:
        """Make the spin in progress re-check its condition (from any thread)."""
        with self._beside:
            self._beside.notify_all()
        loop, waiter = self.loop, self._waiter
        if loop is None or waiter is None or loop.is_closed():
            return
        if threading.get_ident() == self._spin_thread:
            wake(waiter)
        else:
            post(loop, wake, waiter)

    def require_ok(self, what: str) -> None:
        if not self._ok or self.loop is None:
            self.raise_if_interrupted()  # shut down by a Ctrl-C that came just now: that is what it is
            from .rclpy.exceptions import NotInitializedException

            raise NotInitializedException(f"{what}: rclpy.init() has not been called (or rclpy.shutdown() was)")

    def spin_until(
        self, executor: Any, done: Callable[[], bool], timeout_sec: float | None, *, raise_on_shutdown: bool,
        admissions: int | None = None, beside: bool = False,
    ) -> bool:
        """Run the loop in this thread until ``done()`` or ``timeout_sec``; whether ``done()`` held.

        ``admissions`` caps how many program callbacks may start meanwhile (``spin_once``: 1).
        ``beside``: when another thread runs the loop, wait for ``done()`` beside it (a blocking
        call's wait) instead of raising as a second spin of the same executor does.
        """
        self.raise_if_interrupted()  # a Ctrl-C that came between two passes of a spin loop
        self.require_ok("spin")
        loop = self.loop
        assert loop is not None
        if loop.is_running():
            if self._spin_thread == threading.get_ident():
                raise RuntimeError(
                    "spin called from inside a callback: the executor is already spinning in this thread "
                    "(rclpy would deadlock here; use call_async / send_goal_async and a done callback)"
                )
        if not self._spin_lock.acquire(blocking=False):
            if not beside and (self.executor is executor or executor is None):
                raise RuntimeError("the executor is already spinning in another thread (rclpy raises here too)")
            return self._wait_beside(
                executor, done, timeout_sec, raise_on_shutdown=raise_on_shutdown, admissions=admissions
            )
        shut_by_callback = False
        try:
            self._bind_thread()
            previous, self.executor = self.executor, executor

            async def run() -> bool:
                nonlocal shut_by_callback
                deadline = None if timeout_sec is None or timeout_sec < 0 else loop.time() + timeout_sec
                await asyncio.sleep(0)
                try:
                    while True:
                        # The waiter exists before done() is asked: a wake() from another thread
                        # right after the answer (an executor shut down, the condition met) finds
                        # it. Made after, such a wake found none and was lost: the spin slept on
                        # with its condition met (a spinner thread never saw rclpy.shutdown()).
                        waiter = self._waiter = loop.create_future()
                        if self._exit is not None:
                            return False
                        if done():
                            return True
                        if not self._ok:
                            shut_by_callback = getattr(self, "_shutdown_from_callback", False)
                            return False
                        remaining = None if deadline is None else deadline - loop.time()
                        if remaining is not None and remaining <= 0:
                            return False
                        try:
                            await asyncio.wait_for(asyncio.shield(waiter), remaining)
                        except TimeoutError:
                            pass
                finally:
                    self._waiter = None

            # before the loop runs: work queued while nobody spun (a message published from
            # the main thread) must not start ahead of the cap
            self._open_admissions(admissions)
            try:
                result = _run(loop, run())
            finally:
                self.executor = previous
                self._spin_thread = None
        finally:
            self._spin_lock.release()
        if self._interrupted:
            self._interrupted = False
            self._close_if_idle()
            raise KeyboardInterrupt
        if self._exit is not None:
            exc, self._exit = self._exit, None
            raise exc
        if not self._ok:
            self._close_if_idle()
            if raise_on_shutdown and not shut_by_callback and not result:
                raise ExternalShutdownException()
        return result

    def _wait_beside(
        self, executor: Any, done: Callable[[], bool], timeout_sec: float | None, *, raise_on_shutdown: bool,
        admissions: int | None = None,
    ) -> bool:
        """Another executor spins in another thread: it runs the whole graph, so wait for ``done()``.

        rclpy lets two executors spin in two threads (use_logger_service.py spins one node in a
        thread and waits on a service reply in the main one); aiorobot has one loop, which
        the other thread is running. Returns whether ``done()`` held, as ``spin_until``.
        """
        deadline = None if timeout_sec is None or timeout_sec < 0 else time.monotonic() + timeout_sec
        with self._beside:
            while not done():
                if not self._ok:
                    if raise_on_shutdown:
                        raise ExternalShutdownException()
                    return False
                if not self._spin_lock.locked():  # the other spin ended: spin here instead
                    break
                remaining = None if deadline is None else deadline - time.monotonic()
                if remaining is not None and remaining <= 0:
                    return False
                # bounded, so a spin that ends without a wake() is noticed
                self._beside.wait(0.05 if remaining is None else min(remaining, 0.05))
            else:
                return True
        remaining = None if deadline is None else max(0.0, deadline - time.monotonic())
        # the caller's own executor (not whichever spun last), and beside again should another
        # thread take the loop first: the old self.executor here made that race raise "already
        # spinning in another thread"
        return self.spin_until(
            executor, done, remaining, raise_on_shutdown=raise_on_shutdown, admissions=admissions, beside=True
        )

    def run_sync(self, coro: Coroutine[Any, Any, T], what: str) -> T:
        """Run ``coro`` to its end from synchronous code (rclpy's blocking calls)."""
        self.require_ok(what)
        loop = self.loop
        assert loop is not None
        if loop.is_running() or self._spin_lock.locked():
            if self._spin_thread == threading.get_ident():
                coro.close()
                raise RuntimeError(
                    f"{what} blocks until the executor handles the reply, but it was called from a callback "
                    "the executor is running in this thread: it would deadlock (as in rclpy). Use the "
                    "_async form with a done callback, or a MultiThreadedExecutor and a ReentrantCallbackGroup"
                )
            return asyncio.run_coroutine_threadsafe(coro, loop).result()
        task: asyncio.Future[T] | None = None

        def done() -> bool:
            return task is not None and task.done()

        def start() -> None:
            nonlocal task
            task = asyncio.ensure_future(coro, loop=loop)
            task.add_done_callback(lambda _t: self.wake())

        # thread-safe: another thread may start running the loop between the check above and
        # here; a plain call_soon would then sit unseen while that loop sleeps in select(),
        # and this blocking call would wait beside it forever
        loop.call_soon_threadsafe(start)
        try:
            self.spin_until(self.executor, done, None, raise_on_shutdown=False, beside=True)
        except BaseException:
            if task is not None:
                task.cancel()
            else:
                coro.close()
            raise
        if task is None or not task.done():
            if task is not None:
                task.cancel()
            else:
                coro.close()
            from .rclpy.exceptions import NotInitializedException

            raise NotInitializedException(f"{what}: the context was shut down before it finished")
        return task.result()

    # -- internals ------------------------------------------------------------------

    def _bind_thread(self) -> None:
        """Make the calling thread the loop's: aiorobot checks thread ids to choose thread-safe paths."""
        tid = threading.get_ident()
        self._spin_thread = tid
        if self.runtime is not None:
            adopt_thread(self.runtime)

    def _request_shutdown(self) -> None:
        self._ok = False
        self._shutdown_from_callback = self.in_callback()
        callbacks, self._on_shutdown = self._on_shutdown, []
        for cb in callbacks:
            try:
                cb()
            except Exception:  # pragma: no cover - a user hook
                import logging

                logging.getLogger("rclpy").error("on_shutdown callback %r raised", cb, exc_info=True)
        self.wake()
        runtime = self.runtime
        if runtime is not None:
            runtime.shutdown()

    def _close_if_idle(self) -> None:
        """Close the runtime and the loop once no thread runs the loop."""
        with self._lock:
            loop, runtime = self.loop, self.runtime
            if self._ok or self._closed or loop is None or runtime is None:
                return
            if loop.is_running() or self._spin_lock.locked():
                return  # the spinning thread closes it on its way out
            self._closed = True
            self._restore_signal_handlers()
            try:
                _run(loop, runtime.__aexit__(None, None, None))
                _run(loop, loop.shutdown_asyncgens())
            finally:
                loop.close()
                self.loop = None
                self.runtime = None

    def _install_signal_handlers(self) -> None:
        if threading.current_thread() is not threading.main_thread():
            return

        def on_sigint(signum: int, frame: Any) -> None:
            self._ok = False
            self._shutdown_from_callback = False
            loop, runtime = self.loop, self.runtime
            if loop is not None and runtime is not None and not loop.is_closed():
                loop.call_soon_threadsafe(runtime.shutdown)
                # a spin of this thread, its loop running or about to (run_until_complete between
                # registering its done callback and running the loop) or just stopped: raised here,
                # the KeyboardInterrupt would leave that callback to stop the loop's next run
                spinning_here = self._spin_thread == threading.get_ident()
                if (spinning_here or self._main_spin_depth > 0) and not self._interrupted:
                    # Raising here would leave the KeyboardInterrupt inside whichever task step runs
                    # ("Task exception was never retrieved"). Wake the spin instead: it raises
                    # KeyboardInterrupt from the spin call, where rclpy raises it. A callback that blocks
                    # the loop is interrupted by a second Ctrl-C, which raises at once.
                    self._interrupted = True
                    loop.call_soon_threadsafe(self.wake)
                    return
            raise KeyboardInterrupt

        def on_sigterm(signum: int, frame: Any) -> None:
            self._ok = False
            self._shutdown_from_callback = False
            loop = self.loop
            if loop is not None and not loop.is_closed():
                loop.call_soon_threadsafe(self.wake)
                if self.runtime is not None:
                    loop.call_soon_threadsafe(self.runtime.shutdown)

        for sig, handler in ((signal.SIGINT, on_sigint), (signal.SIGTERM, on_sigterm)):
            try:
                self._saved_handlers[sig] = signal.signal(sig, handler)
            except (ValueError, OSError):  # pragma: no cover
                pass
        previous_hook = self._saved_unraisablehook = sys.unraisablehook

        def redeliver_swallowed_interrupt(unraisable: Any) -> None:
            # Python runs a signal handler wherever the main thread is, a finaliser or a weakref
            # callback included (a WeakSet's, during garbage collection). An exception raised there is
            # printed as "Exception ignored in ..." and dropped, so the program would miss its Ctrl-C.
            # Deliver it again: the handler runs once more at the main thread's next instruction.
            tb = unraisable.exc_traceback
            while tb is not None and tb.tb_next is not None:
                tb = tb.tb_next
            if unraisable.exc_type is KeyboardInterrupt and tb is not None and tb.tb_frame.f_code is on_sigint.__code__:
                threading.Thread(target=_signal_main_thread_after, args=(sys._getframe(),), daemon=True,
                                 name="aiorobot-redeliver-sigint").start()
                return
            previous_hook(unraisable)

        sys.unraisablehook = redeliver_swallowed_interrupt

    def _restore_signal_handlers(self) -> None:
        if threading.current_thread() is not threading.main_thread():
            return
        for sig, previous in self._saved_handlers.items():
            signal.signal(sig, previous if previous is not None else signal.SIG_DFL)
        self._saved_handlers.clear()
        if self._saved_unraisablehook is not None:
            sys.unraisablehook, self._saved_unraisablehook = self._saved_unraisablehook, None


def _signal_main_thread_after(hook_frame: Any) -> None:
    """SIGINT to the main thread once it has left ``hook_frame`` (sys.unraisablehook's).

    Signalled while the hook still runs, the handler would raise in the hook, where the exception
    is dropped again; a real signal (not ``_thread.interrupt_main``) also ends a ``time.sleep``.
    """
    main = threading.main_thread().ident
    assert main is not None
    deadline, frame = time.monotonic() + 5.0, None
    while time.monotonic() < deadline:
        frame = sys._current_frames().get(main)
        while frame is not None and frame is not hook_frame:
            frame = frame.f_back
        if frame is None:
            break
        time.sleep(0.0005)
    del hook_frame, frame
    signal.pthread_kill(main, signal.SIGINT)


def _at_exit(ref: weakref.ref[Context]) -> None:
    """The program's main thread has ended: end the context once the program's own threads have.

    A program may end without ``rclpy.shutdown()`` (teleop_twist_keyboard does). With rclpy the
    process then ends; here the runtime's zenoh session keeps non-daemon callback threads
    (zenoh-python's) alive, so Python would wait for them forever, and the SIGTERM handler, which
    only wakes a spin, could not end it either. Python calls this before it joins its threads:
    it waits for the threads the program started (a spinner thread keeps the process, as with
    rclpy), then shuts the context down, which closes the session and ends those threads. A
    Ctrl-C meanwhile shuts down at once.
    """
    context = ref()
    if context is None or context._closed:
        return
    me = threading.current_thread()
    try:
        while not context._closed:
            waiting = [t for t in threading.enumerate() if t is not me and _program_thread(t)]
            if not waiting:
                break
            waiting[0].join()
    except KeyboardInterrupt:
        pass
    context.try_shutdown()


def _program_thread(thread: threading.Thread) -> bool:
    """A live non-daemon thread the program started (not zenoh's callback threads, not a thread pool's)."""
    if thread.daemon or thread is threading.main_thread() or not thread.is_alive():
        return False
    if "pyo3-closure" in thread.name:  # zenoh-python's: they end when the session closes
        return False
    target = getattr(thread, "_target", None)
    # thread pools (the runtime's, MultiThreadedExecutor's, asyncio's): concurrent.futures joins them itself
    return not (getattr(target, "__module__", None) or "").startswith("concurrent.futures")


def _run(loop: asyncio.AbstractEventLoop, coro: Coroutine[Any, Any, T]) -> T:
    """``loop.run_until_complete(coro)``, also from code running on another asyncio loop.

    A program may drive rclpy from its own loop (ros2/examples' ``client_asyncio.py`` calls
    ``rclpy.init`` and ``spin_once`` inside coroutines): rclpy's executor does not care, but
    asyncio refuses to run a loop while the thread has a running one. That outer loop is
    blocked for as long as this call lasts (as it is by rclpy's spin_once), so the context's
    loop runs nested and the outer one is made the running loop again afterwards.
    """
    outer = asyncio.events._get_running_loop()
    if outer is None:
        return loop.run_until_complete(coro)
    asyncio.events._set_running_loop(None)
    try:
        return loop.run_until_complete(coro)
    finally:
        asyncio.events._set_running_loop(outer)


def _build_node(spec: str) -> Any:
    import importlib

    module_name, sep, attr = spec.partition(":")
    if not sep or not module_name or not attr:
        raise ValueError(f"--node: expected module:Class, found {spec!r}")
    factory = getattr(importlib.import_module(module_name), attr)
    return factory()


_default: Context | None = None


def default_context() -> Context:
    global _default
    if _default is None:
        _default = Context()
    return _default
