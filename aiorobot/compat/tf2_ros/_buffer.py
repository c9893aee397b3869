"""tf2_ros's ``Buffer`` (and tf2_py's ``BufferCore``) over :mod:`aiorobot.tf`'s.

The maths, the caches and the exceptions are aiorobot.tf's; this module adds tf2_py's
method names (``set_transform_static``, ``lookup_transform_core``, ...), tf2_ros's
``timeout`` arguments (which block the calling thread, see :mod:`._wait`) and its
``wait_for_transform_async`` futures.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import Any

from ... import tf as _tf
from ..._core._future import Future
from ..._core._time import Duration
from ...tf._buffer import _timeout_seconds
from ...tf._buffer_core import DEFAULT_CACHE_TIME_SEC
from ...tf._msgs import time_ns
from ._interface import BufferInterface
from ._wait import block_until

__all__ = ["Buffer", "BufferCore", "TimeoutException"]


class TimeoutException(_tf.TransformException):
    """A tf2 request timed out (tf2_py's; tf2_ros's ``BufferClient`` raises it)."""


def _cache_seconds(cache_time: Any) -> float:
    if cache_time is None:
        return DEFAULT_CACHE_TIME_SEC
    ns = getattr(cache_time, "nanoseconds", None)
    if isinstance(ns, int) and not isinstance(cache_time, (int, float)):
        return ns / 1e9
    return cache_time  # type: ignore[no-any-return]  # aiorobot's check names a bad value


class _CoreNames:
    """tf2_py ``BufferCore``'s method names over aiorobot's :class:`~aiorobot.tf.BufferCore`."""

    def set_transform(self, transform: Any, authority: str, *, static: bool = False) -> None:
        """Insert ``transform``; a malformed one is logged and dropped, as tf2 does."""
        try:
            _tf.BufferCore.set_transform(self, transform, authority, static=static)  # type: ignore[arg-type]
        except _tf.TransformException as exc:
            from ..rclpy.logging import get_logger

            get_logger("tf2_buffer").error(f"dropped a transform from {authority!r}: {exc}")

    def set_transform_static(self, transform: Any, authority: str) -> None:
        self.set_transform(transform, authority, static=True)

    def lookup_transform_core(self, target_frame: str, source_frame: str, time: Any) -> Any:
        return _tf.BufferCore.lookup_transform(self, target_frame, source_frame, time)  # type: ignore[arg-type]

    def lookup_transform_full_core(
        self, target_frame: str, target_time: Any, source_frame: str, source_time: Any, fixed_frame: str
    ) -> Any:
        return _tf.BufferCore.lookup_transform_full(
            self, target_frame, target_time, source_frame, source_time, fixed_frame  # type: ignore[arg-type]
        )

    def can_transform_core(self, target_frame: str, source_frame: str, time: Any) -> tuple[bool, str]:
        return _tf.BufferCore.can_transform(  # type: ignore[return-value]
            self, target_frame, source_frame, time, return_debug_tuple=True  # type: ignore[arg-type]
        )

    def can_transform_full_core(
        self, target_frame: str, target_time: Any, source_frame: str, source_time: Any, fixed_frame: str
    ) -> tuple[bool, str]:
        return _tf.BufferCore.can_transform_full(  # type: ignore[return-value]
            self, target_frame, target_time, source_frame, source_time, fixed_frame,  # type: ignore[arg-type]
            return_debug_tuple=True,
        )


class BufferCore(_CoreNames, _tf.BufferCore):
    """tf2_py's ``BufferCore(cache_time=Duration(seconds=10))``: lookups that never wait."""

    def __init__(self, cache_time: Any = None) -> None:
        _tf.BufferCore.__init__(self, _cache_seconds(cache_time))

    def lookup_transform(self, target_frame: str, source_frame: str, time: Any) -> Any:
        return self.lookup_transform_core(target_frame, source_frame, time)


class Buffer(_CoreNames, _tf.Buffer, BufferInterface):
    """tf2_ros's ``Buffer(cache_time=None, node=None)``.

    ``lookup_transform``, ``can_transform`` (and their ``_full`` forms) with a ``timeout``
    block the calling thread up to that long while the listener keeps receiving, also from a
    plain callback of a SingleThreadedExecutor; then they raise (or return) what holds, as
    tf2_ros. ``wait_for_transform_async`` returns an rclpy ``Future`` that is done with the
    transform once it is available; ``lookup_transform_async`` is a coroutine.

    rclpy difference: ``Buffer(node=...)`` does not offer the ``tf2_frames`` service (aiorobot has
    no ``tf2_msgs/srv/FrameGraph``); ``all_frames_as_yaml()`` gives the same text.
    """

    def __init__(self, cache_time: Any = None, node: Any = None) -> None:
        _tf.Buffer.__init__(self, _cache_seconds(cache_time))
        BufferInterface.__init__(self)
        self._new_data_callbacks: list[Callable[[], None]] = []
        self._callbacks_lock = threading.Lock()
        self._context = getattr(node, "_context", None)
        if node is not None:
            self.clock = node.get_clock()
        else:
            from ..._core._clock import Clock

            self.clock = Clock()
        # as tf2_ros: a jump back in time (a bag looping, sim time restarting) clears the buffer
        from ..._core._clock import JumpThreshold

        threshold = JumpThreshold(min_forward=None, min_backward=Duration(seconds=-1), on_clock_change=True)
        self.jump_handle = self.clock.create_jump_callback(threshold, post_callback=self.time_jump_callback)

    # ------------------------------------------------------------------ new data

    def _on_insert(self) -> None:
        _tf.Buffer._on_insert(self)
        with self._callbacks_lock:
            callbacks = list(self._new_data_callbacks)
        for callback in callbacks:
            callback()

    def _subscribe(self, callback: Callable[[], None]) -> Callable[[], None]:
        """Call ``callback()`` after every insert until the returned function is called."""
        with self._callbacks_lock:
            self._new_data_callbacks.append(callback)

        def unsubscribe() -> None:
            with self._callbacks_lock:
                if callback in self._new_data_callbacks:
                    self._new_data_callbacks.remove(callback)

        return unsubscribe

    def _block_until(self, ready: Callable[[], bool], timeout: Any) -> None:
        seconds = _timeout_seconds(timeout)
        if seconds > 0:
            block_until(ready, seconds, self._subscribe, self._context)

    # ------------------------------------------------------------------ tf2_ros's blocking forms

    def lookup_transform(  # type: ignore[override]
        self, target_frame: str, source_frame: str, time: Any, timeout: Any = Duration()
    ) -> Any:
        """The transform from ``source_frame`` to ``target_frame`` at ``time``, waiting up to ``timeout``.

        Raises LookupException, ConnectivityException, ExtrapolationException or
        InvalidArgumentException when it is still not available after ``timeout``.

        rclpy difference: called from a plain callback of a SingleThreadedExecutor, the wait
        keeps the listener (and every other callback not in the caller's mutually exclusive
        group) running, so the transform can arrive during it; under tf2_ros the executor's
        only thread sleeps in the callback and the lookup can only time out.
        """
        self.can_transform(target_frame, source_frame, time, timeout)
        return self.lookup_transform_core(target_frame, source_frame, time)

    def lookup_transform_full(  # type: ignore[override]
        self, target_frame: str, target_time: Any, source_frame: str, source_time: Any, fixed_frame: str,
        timeout: Any = Duration(),
    ) -> Any:
        self.can_transform_full(target_frame, target_time, source_frame, source_time, fixed_frame, timeout)
        return self.lookup_transform_full_core(target_frame, target_time, source_frame, source_time, fixed_frame)

    def can_transform(  # type: ignore[override]
        self, target_frame: str, source_frame: str, time: Any, timeout: Any = Duration(),
        return_debug_tuple: bool = False,
    ) -> bool | tuple[bool, str]:
        time_ns(time)  # a bad time fails here, not after the timeout
        self._block_until(lambda: self.can_transform_core(target_frame, source_frame, time)[0], timeout)
        result = self.can_transform_core(target_frame, source_frame, time)
        return result if return_debug_tuple else result[0]

    def can_transform_full(  # type: ignore[override]
        self, target_frame: str, target_time: Any, source_frame: str, source_time: Any, fixed_frame: str,
        timeout: Any = Duration(), return_debug_tuple: bool = False,
    ) -> bool | tuple[bool, str]:
        args = (target_frame, target_time, source_frame, source_time, fixed_frame)
        time_ns(target_time), time_ns(source_time)
        self._block_until(lambda: self.can_transform_full_core(*args)[0], timeout)
        result = self.can_transform_full_core(*args)
        return result if return_debug_tuple else result[0]

    # ------------------------------------------------------------------ futures and coroutines

    def _future_when(self, ready: Callable[[], bool], get: Callable[[], Any]) -> Future[Any]:
        fut: Future[Any] = Future()
        if ready():
            fut.set_result(get())
            return fut

        def on_new_data() -> None:
            if fut.done():
                return
            try:
                if ready():
                    fut.set_result(get())
            except Exception as exc:
                fut.set_exception(exc)

        unsubscribe = self._subscribe(on_new_data)
        fut.add_done_callback(lambda _f: unsubscribe())
        return fut

    def wait_for_transform_async(self, target_frame: str, source_frame: str, time: Any) -> Future[Any]:
        """A Future done with the transform as soon as it is available (it never times out, as tf2_ros)."""
        time_ns(time)
        return self._future_when(
            lambda: self.can_transform_core(target_frame, source_frame, time)[0],
            lambda: self.lookup_transform_core(target_frame, source_frame, time),
        )

    def wait_for_transform_full_async(
        self, target_frame: str, target_time: Any, source_frame: str, source_time: Any, fixed_frame: str
    ) -> Future[Any]:
        args = (target_frame, target_time, source_frame, source_time, fixed_frame)
        time_ns(target_time), time_ns(source_time)
        return self._future_when(
            lambda: self.can_transform_full_core(*args)[0], lambda: self.lookup_transform_full_core(*args)
        )

    async def lookup_transform_async(  # type: ignore[override]
        self, target_frame: str, source_frame: str, time: Any, timeout_sec: float | None = None
    ) -> Any:
        """tf2_ros's coroutine; aiorobot's ``timeout_sec`` (raising the tf exception) is kept as an extra."""
        if timeout_sec is not None:
            return await _tf.Buffer.lookup_transform_async(self, target_frame, source_frame, time, timeout_sec)
        await self.wait_for_transform_async(target_frame, source_frame, time)
        return self.lookup_transform_core(target_frame, source_frame, time)

    async def lookup_transform_full_async(  # type: ignore[override]
        self, target_frame: str, target_time: Any, source_frame: str, source_time: Any, fixed_frame: str,
        timeout_sec: float | None = None,
    ) -> Any:
        args = (target_frame, target_time, source_frame, source_time, fixed_frame)
        if timeout_sec is not None:
            return await _tf.Buffer.lookup_transform_full_async(self, *args, timeout_sec)
        await self.wait_for_transform_full_async(*args)
        return self.lookup_transform_full_core(*args)

    # ------------------------------------------------------------------ tf2_ros's transform (registered types)

    transform = BufferInterface.transform  # type: ignore[assignment]
    transform_full = BufferInterface.transform_full  # type: ignore[assignment]

    def time_jump_callback(self, time_jump: Any) -> None:
        """The clock jumped back in time: forget the dynamic transforms (tf2_ros's)."""
        from ..rclpy.logging import get_logger

        get_logger("tf2_buffer").warning("Detected jump back in time. Clearing tf buffer.")
        self.clear()
