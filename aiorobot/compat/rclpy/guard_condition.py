"""``rclpy.guard_condition``: a condition any thread triggers and the executor answers with a callback.

As in rclpy, ``node.create_guard_condition(callback)`` makes one the node's executor
waits on; ``trigger()`` (from any thread, a callback included) makes its callback run in
a later pass of the executor, under its callback group. Triggers that arrive before the
callback starts coalesce into one call, as rcl's guard condition is a flag. A guard
condition made directly with ``GuardCondition(callback, callback_group)`` is on no
node: rclpy's executor never waits on it, so its callback never runs here either.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import Any

from ..._core._groups import CallbackGroup
from ...lowlevel import node_loop, run_callback
from .._context import Context, default_context
from .._dispatch import wrap_callback
from .exceptions import InvalidHandle

__all__ = ["GuardCondition"]


class GuardCondition:
    """rclpy's ``GuardCondition(callback, callback_group, context=None)``."""

    def __init__(self, callback: Callable[[], Any] | None, callback_group: CallbackGroup | None, context: Context | None = None) -> None:
        self._context = context or default_context()
        self.callback = callback
        self.callback_group = callback_group
        self._node: Any = None
        self._triggered = False
        self._destroyed = False
        self._lock = threading.Lock()

    def __repr__(self) -> str:
        where = f" of {self._node.get_fully_qualified_name()}" if self._node is not None else ""
        return f"<GuardCondition{where}>"

    def trigger(self) -> None:
        """Make the executor run the callback once (again, if it already ran)."""
        if self._destroyed:
            raise InvalidHandle("GuardCondition.trigger: the guard condition was destroyed")
        with self._lock:
            if self._triggered:
                return
            self._triggered = True
        ctx = self._context
        loop = ctx.loop
        if loop is None or loop.is_closed():
            return
        if threading.get_ident() == ctx._spin_thread and loop.is_running():
            loop.call_soon(self._ready)
        else:
            loop.call_soon_threadsafe(self._ready)

    def destroy(self) -> None:
        self._destroyed = True
        node, self._node = self._node, None
        if node is not None and self in node._guards_list():
            node._guards_list().remove(self)

    # -- on the loop ------------------------------------------------------------------

    def _attach(self, node: Any) -> None:
        self._node = node
        self.callback_group = self.callback_group or node.default_callback_group

    def _ready(self) -> None:
        node = self._node
        if node is None or self._destroyed or node_loop(node) is None:
            return  # on no executor: the trigger stays set, as an unwaited rcl guard condition's
        with self._lock:
            self._triggered = False
        if self.callback is None:
            self._context.callback_finished()
            return
        callback = wrap_callback(self._context, self.callback)
        node.create_task(run_callback(node, self, self.callback_group, callback), name=f"guard condition of {node.get_fully_qualified_name()}")
