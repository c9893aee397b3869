"""`Buffer`: the tf2 buffer core plus waiting for data and transforming data.

Waiting is event driven: every insert re-checks the pending waiters and wakes
the ones whose transform became available, on the waiter's own event loop
(``call_soon_threadsafe`` when the insert runs on another thread). No waiter
ever polls or sleeps.
"""

from __future__ import annotations

import asyncio
import threading
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._core._handoff import call_on, wake
from ._buffer_core import DEFAULT_CACHE_TIME_SEC, BufferCore, check_frame_id_syntax
from ._cache import display_time
from ._conversions import check_supported
from ._exceptions import ExtrapolationException, TransformException
from ._math import _q_to_m
from ._msgs import make_transform_stamped, stamp_msg, time_ns

__all__ = ["Buffer"]


@dataclass(eq=False)
class _Waiter:
    target: Any
    source: Any
    time_ns: int
    # lookup_transform_full waits: (target_time_ns, source_time_ns, fixed_frame)
    full: tuple[int, int, Any] | None = None
    loop: asyncio.AbstractEventLoop | None = None
    future: asyncio.Future[None] | None = None
    event: threading.Event | None = field(default=None)
    failure: TransformException | None = None


def _timeout_seconds(timeout: Any) -> float:
    """tf2_ros's ``timeout``: a Duration (anything with integer ``nanoseconds``) or a number of seconds."""
    ns = getattr(timeout, "nanoseconds", None)
    if isinstance(ns, int) and not isinstance(timeout, (int, float)):
        seconds = ns / 1e9
    elif isinstance(timeout, (int, float)) and not isinstance(timeout, bool):
        seconds = float(timeout)
    else:
        raise TypeError(f"timeout: expected a Duration or a number of seconds, got {timeout!r}")
    if seconds < 0:
        raise ValueError(f"timeout: expected >= 0, got {timeout!r}")
    return seconds


def _check_timeout(timeout_sec: float | None) -> float | None:
    if timeout_sec is None:
        return None
    if isinstance(timeout_sec, bool) or not isinstance(timeout_sec, (int, float)) or timeout_sec < 0:
        raise ValueError(f"expected timeout_sec >= 0 seconds or None, got {timeout_sec!r}")
    return float(timeout_sec)


class Buffer(BufferCore):
    """A tf2 transform buffer (see :class:`BufferCore`) that can wait and transform data.

    Parameters
    ----------
    cache_time_sec
        History kept per dynamic frame, in seconds; a :class:`~aiorobot.Duration` works
        too (tf2_ros's ``Buffer(cache_time)``).
    cache_time
        tf2_ros's keyword for the same, a Duration.
    """

    def __init__(self, cache_time_sec: Any = DEFAULT_CACHE_TIME_SEC, *, cache_time: Any = None) -> None:
        if cache_time is not None:
            cache_time_sec = cache_time
        if hasattr(cache_time_sec, "nanoseconds") and not isinstance(cache_time_sec, (int, float)):
            cache_time_sec = cache_time_sec.nanoseconds / 1e9
        super().__init__(cache_time_sec)
        self._waiters_lock = threading.Lock()
        self._waiters: list[_Waiter] = []

    # ------------------------------------------------------------------ waking waiters

    def _state(self, w: _Waiter) -> tuple[bool, TransformException | None]:
        """(done, failure): done with failure None means available (waiters lock held)."""
        if w.full is not None:
            target_t, source_t, fixed = w.full
            ok, _ = self._can_transform_full_raw(w.target, target_t, w.source, source_t, fixed)
            return ok, None
        ok, _ = self._can_transform_raw(w.target, w.source, w.time_ns)
        if ok:
            return True, None
        too_old = self._too_old(w.target, w.source, w.time_ns)
        return (too_old is not None), too_old

    def _too_old(self, target: Any, source: Any, t: int) -> TransformException | None:
        """tf2 gives up on a request older than the latest common time minus the cache length."""
        if t == 0:
            return None
        with self._lock:
            target_id = self._ids.get(target, 0) if isinstance(target, str) else 0
            source_id = self._ids.get(source, 0) if isinstance(source, str) else 0
            if target_id == 0 or source_id == 0:
                return None
            try:
                latest = self._latest_common_time(target_id, source_id)
            except TransformException:
                return None
        if latest != 0 and t + self._cache_ns < latest:
            return ExtrapolationException(
                f"Lookup would require extrapolation into the past.  Requested time {display_time(t)} "
                f"is more than the cache length ({self.cache_time_sec:g} s) older than the latest "
                f"data at time {display_time(latest)}, when looking up transform from frame "
                f"[{source}] to frame [{target}]; it can never become available"
            )
        return None

    def _on_insert(self) -> None:
        if not self._waiters:
            return
        ready: list[_Waiter] = []
        with self._waiters_lock:
            keep = []
            for w in self._waiters:
                done, failure = self._state(w)
                if done:
                    w.failure = failure
                    ready.append(w)
                else:
                    keep.append(w)
            self._waiters = keep
        for w in ready:
            self._wake(w)

    @staticmethod
    def _wake(w: _Waiter) -> None:
        if w.event is not None:
            w.event.set()
            return
        assert w.loop is not None and w.future is not None
        call_on(w.loop, wake, w.future, w.failure)  # a closed loop: nobody is waiting any more

    def _register(self, w: _Waiter) -> bool:
        """Add a waiter unless already satisfied; True when it must wait. Raises a final failure."""
        if w.target != w.source or w.full is not None:
            # ids that can never become valid fail at once instead of at the timeout
            check_frame_id_syntax(w.target, "wait_for_transform argument target_frame")
            check_frame_id_syntax(w.source, "wait_for_transform argument source_frame")
            if w.full is not None:
                check_frame_id_syntax(w.full[2], "wait_for_transform argument fixed_frame")
        with self._waiters_lock:
            done, failure = self._state(w)
            if done:
                if failure is not None:
                    raise failure
                return False
            self._waiters.append(w)
            return True

    def _unregister(self, w: _Waiter) -> None:
        with self._waiters_lock:
            if w in self._waiters:
                self._waiters.remove(w)

    def _timeout_error(self, w: _Waiter, timeout_sec: float) -> TransformException | None:
        """The error that still holds after a timeout, or None if the data just arrived."""
        try:
            if w.full is not None:
                self._lookup_full_raw(w.target, w.full[0], w.source, w.full[1], w.full[2])
            else:
                self._lookup_raw(w.target, w.source, w.time_ns, "wait_for_transform")
        except TransformException as exc:
            return type(exc)(f"Timed out after {timeout_sec:g} s waiting for the transform: {exc}")
        return None

    # ------------------------------------------------------------------ waiting (async)

    async def _wait(self, w: _Waiter, timeout_sec: float | None) -> None:
        timeout_sec = _check_timeout(timeout_sec)
        w.loop = asyncio.get_running_loop()
        w.future = w.loop.create_future()
        if not self._register(w):
            return
        try:
            async with asyncio.timeout(timeout_sec):
                await w.future
        except TimeoutError:
            assert timeout_sec is not None
            error = self._timeout_error(w, timeout_sec)
            if error is not None:
                raise error from None
        finally:
            self._unregister(w)

    async def wait_for_transform(
        self, target_frame: str, source_frame: str, time: Any, timeout_sec: float | None = None
    ) -> None:
        """Return as soon as ``lookup_transform(target_frame, source_frame, time)`` can succeed.

        Woken by inserts (from any thread or event loop), never by polling.
        ``timeout_sec=None`` waits forever.

        Raises
        ------
        TransformException
            On timeout: the error the lookup still gives (``LookupException`` for a
            frame that never appeared, ``ExtrapolationException`` for data that does
            not reach ``time``...), its message prefixed with the timeout. At once,
            with ``ExtrapolationException``, for a time older than the cache can hold.

        rclpy difference: tf2_ros has no awaitable with a timeout (``can_transform``
        with a timeout returns ``False``, ``wait_for_transform_async`` never times
        out); this one raises the tf exception that still holds, so the caller
        learns why (which frame is missing, how far the data reaches).
        """
        await self._wait(_Waiter(target_frame, source_frame, time_ns(time)), timeout_sec)

    async def wait_for_transform_full(
        self,
        target_frame: str,
        target_time: Any,
        source_frame: str,
        source_time: Any,
        fixed_frame: str,
        timeout_sec: float | None = None,
    ) -> None:
        """As `wait_for_transform`, for `lookup_transform_full`."""
        full = (time_ns(target_time), time_ns(source_time), fixed_frame)
        await self._wait(_Waiter(target_frame, source_frame, full[0], full=full), timeout_sec)

    async def lookup_transform_async(
        self, target_frame: str, source_frame: str, time: Any, timeout_sec: float | None = None
    ) -> Any:
        """`lookup_transform`, waiting up to ``timeout_sec`` for the data to arrive."""
        await self.wait_for_transform(target_frame, source_frame, time, timeout_sec)
        return self.lookup_transform(target_frame, source_frame, time)

    async def lookup_transform_full_async(
        self,
        target_frame: str,
        target_time: Any,
        source_frame: str,
        source_time: Any,
        fixed_frame: str,
        timeout_sec: float | None = None,
    ) -> Any:
        """`lookup_transform_full`, waiting up to ``timeout_sec`` for the data to arrive."""
        await self.wait_for_transform_full(
            target_frame, target_time, source_frame, source_time, fixed_frame, timeout_sec
        )
        return self.lookup_transform_full(target_frame, target_time, source_frame, source_time, fixed_frame)

    # ------------------------------------------------------------------ waiting (blocking)

    def _wait_blocking(self, w: _Waiter, timeout_sec: float | None) -> None:
        """Block this thread until available (for worker threads, never an event loop thread)."""
        timeout_sec = _check_timeout(timeout_sec)
        if not timeout_sec:
            return
        try:
            asyncio.get_running_loop()
        except RuntimeError:
            pass
        else:
            raise RuntimeError(
                "a blocking wait (timeout_sec > 0) would stall this thread's event loop and the "
                "inserts it runs; use 'await buffer.transform_async(...)' or "
                "'await buffer.lookup_transform_async(...)' instead"
            )
        w.event = threading.Event()
        if not self._register(w):
            return
        try:
            if w.event.wait(timeout_sec) and w.failure is not None:
                raise w.failure
        finally:
            self._unregister(w)

    # ------------------------------------------------------------------ tf2_ros's blocking forms

    def lookup_transform(self, target_frame: str, source_frame: str, time: Any, timeout: Any = None) -> Any:
        """tf2_ros's ``lookup_transform``: as :meth:`BufferCore.lookup_transform`, and with ``timeout``
        (a :class:`~aiorobot.Duration` or seconds) it first blocks this thread up to that long for the
        data, then raises the tf exception if it is still missing. Blocking is refused on an event
        loop thread: there, ``await lookup_transform_async(...)``.
        """
        if timeout is not None:
            self._wait_blocking(_Waiter(target_frame, source_frame, time_ns(time)), _timeout_seconds(timeout))
        # BufferCore.lookup_transform's two lines, not a super() call: this is the hot path
        t_out, vec, q = self._lookup_raw(target_frame, source_frame, time_ns(time), "lookup_transform")
        return make_transform_stamped(target_frame, source_frame, t_out, vec, q)

    def lookup_transform_full(
        self,
        target_frame: str,
        target_time: Any,
        source_frame: str,
        source_time: Any,
        fixed_frame: str,
        timeout: Any = None,
    ) -> Any:
        """tf2_ros's ``lookup_transform_full``, with ``timeout`` as in :meth:`lookup_transform`."""
        if timeout is not None:
            full = (time_ns(target_time), time_ns(source_time), fixed_frame)
            self._wait_blocking(_Waiter(target_frame, source_frame, full[0], full=full), _timeout_seconds(timeout))
        return super().lookup_transform_full(target_frame, target_time, source_frame, source_time, fixed_frame)

    def can_transform(  # type: ignore[override]
        self, target_frame: str, source_frame: str, time: Any, timeout: Any = None, return_debug_tuple: bool = False
    ) -> bool | tuple[bool, str]:
        """tf2_ros's ``can_transform``: never raises for tf errors; ``timeout`` first blocks this thread
        up to that long for the data (not on an event loop thread)."""
        if timeout is not None:
            self._wait_blocking(_Waiter(target_frame, source_frame, time_ns(time)), _timeout_seconds(timeout))
        return super().can_transform(target_frame, source_frame, time, return_debug_tuple=return_debug_tuple)

    def can_transform_full(  # type: ignore[override]
        self,
        target_frame: str,
        target_time: Any,
        source_frame: str,
        source_time: Any,
        fixed_frame: str,
        timeout: Any = None,
        return_debug_tuple: bool = False,
    ) -> bool | tuple[bool, str]:
        """tf2_ros's ``can_transform_full``, with ``timeout`` as in :meth:`can_transform`."""
        if timeout is not None:
            full = (time_ns(target_time), time_ns(source_time), fixed_frame)
            self._wait_blocking(_Waiter(target_frame, source_frame, full[0], full=full), _timeout_seconds(timeout))
        return super().can_transform_full(
            target_frame, target_time, source_frame, source_time, fixed_frame, return_debug_tuple=return_debug_tuple
        )

    # ------------------------------------------------------------------ transforming data

    def transform(self, msg: Any, target_frame: str, timeout_sec: float | None = None) -> Any:
        """Express a stamped message in ``target_frame`` at its own ``header.stamp``.

        Supports PointStamped, Vector3Stamped (rotated only), PoseStamped,
        QuaternionStamped and TransformStamped. ``timeout_sec`` blocks the calling
        thread waiting for data (not allowed on an event loop thread: use
        `transform_async` there).
        """
        handler = check_supported(msg)
        source = msg.header.frame_id
        t = time_ns(msg.header.stamp)
        self._wait_blocking(_Waiter(target_frame, source, t), timeout_sec)
        t_out, vec, q = self._lookup_raw(target_frame, source, t, "transform")
        return handler(msg, vec, q, target_frame, stamp_msg(t_out))

    async def transform_async(self, msg: Any, target_frame: str, timeout_sec: float | None = None) -> Any:
        """`transform`, awaiting the data up to ``timeout_sec``."""
        handler = check_supported(msg)
        source = msg.header.frame_id
        t = time_ns(msg.header.stamp)
        await self._wait(_Waiter(target_frame, source, t), timeout_sec)
        t_out, vec, q = self._lookup_raw(target_frame, source, t, "transform")
        return handler(msg, vec, q, target_frame, stamp_msg(t_out))

    def transform_full(
        self, msg: Any, target_frame: str, target_time: Any, fixed_frame: str, timeout_sec: float | None = None
    ) -> Any:
        """Time travel: the message at its stamp, into ``target_frame`` at ``target_time``."""
        handler = check_supported(msg)
        source = msg.header.frame_id
        t_src = time_ns(msg.header.stamp)
        full = (time_ns(target_time), t_src, fixed_frame)
        self._wait_blocking(_Waiter(target_frame, source, full[0], full=full), timeout_sec)
        t_out, vec, q = self._lookup_full_raw(target_frame, full[0], source, t_src, fixed_frame)
        return handler(msg, vec, q, target_frame, stamp_msg(t_out))

    def transform_points(
        self, points: ArrayLike, target_frame: str, source_frame: str, time: Any
    ) -> NDArray[np.float64]:
        """Map an (N, 3) array of points from ``source_frame`` to ``target_frame`` at ``time``.

        One lookup, then a Numba kernel that releases the GIL (so
        ``await node.run_in_thread(buffer.transform_points, ...)`` runs in parallel
        with the event loop). Returns a new float64 array of shape (N, 3).
        """
        pts = check_points(points)
        _t_out, vec, q = self._lookup_raw(target_frame, source_frame, time_ns(time), "transform_points")
        from ._kernels import transform_points_kernel

        R = np.array(_q_to_m(q), dtype=np.float64).reshape(3, 3)
        return transform_points_kernel(pts, R, np.array(vec, dtype=np.float64))


def check_points(points: ArrayLike) -> NDArray[np.float64]:
    """Coerce to a C-contiguous float64 array of shape (N, 3), or raise ValueError."""
    arr = np.ascontiguousarray(points, dtype=np.float64)
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise ValueError(f"expected points of shape (N, 3), got shape {arr.shape}")
    return arr

