"""``rclpy.action``: action servers and clients with rclpy's signatures, on aiorobot's."""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

from ...._core import _actions
from ...._core._actions import CancelResponse, ClientGoalHandle, GoalResponse, GoalStatus, ServerGoalHandle
from ..._missing import module_getattr
from ..._node import raw

__all__ = [
    "ActionClient", "ActionServer", "AsyncActionClient", "CancelResponse", "ClientGoalHandle", "GoalResponse", "GoalStatus",
    "ServerGoalHandle",
]


def _wrap(node: Any, callback: Any) -> Any:
    bridge = getattr(node, "_bridge_callback", None)
    if bridge is not None:  # an AsyncNode: the callback runs on the program's loop
        return bridge(callback)
    wrap = getattr(node, "_wrap", None)
    return callback if wrap is None or callback is None else wrap(callback)[0]


class ActionServer(_actions.ActionServer):
    """rclpy's ``ActionServer(node, action_type, action_name, execute_callback, ...)``."""

    def __init__(
        self, node: Any, action_type: Any, action_name: str, execute_callback: Callable[[Any], Any], *,
        callback_group: Any = None, goal_callback: Any = None, handle_accepted_callback: Any = None,
        cancel_callback: Any = None, goal_service_qos_profile: Any = None, result_service_qos_profile: Any = None,
        cancel_service_qos_profile: Any = None, feedback_pub_qos_profile: Any = None,
        status_pub_qos_profile: Any = None, result_timeout: float = 900,
    ) -> None:
        with raw(node):
            super().__init__(
                node, action_type, action_name, _wrap(node, execute_callback),
                goal_callback=_wrap(node, goal_callback),
                handle_accepted_callback=_wrap(node, handle_accepted_callback),
                cancel_callback=_wrap(node, cancel_callback),
                callback_group=callback_group, result_timeout=result_timeout,
            )

    def register_execute_callback(self, execute_callback: Callable[[Any], Any]) -> None:
        self._execute = _wrap(self.node, execute_callback)


class ActionClient(_actions.ActionClient):
    """rclpy's ``ActionClient(node, action_type, action_name)``: ``wait_for_server`` blocks.

    On an ``rclpy.experimental.AsyncNode`` it is an :class:`AsyncActionClient`, which awaits.
    """

    def __new__(cls, node: Any, *args: Any, **kwargs: Any) -> Any:
        if cls is ActionClient and getattr(node, "_bridge_callback", None) is not None:
            cls = AsyncActionClient
        return super().__new__(cls)

    def __init__(self, node: Any, action_type: Any, action_name: str, *, callback_group: Any = None, **qos: Any) -> None:
        with raw(node):
            super().__init__(node, action_type, action_name, callback_group=callback_group)

    def wait_for_server(self, timeout_sec: float | None = None) -> bool:  # type: ignore[override]
        ctx = self.node._context
        if ctx.in_callback() and ctx.loop is not None and ctx.loop.is_running():
            deadline = None if timeout_sec is None else time.monotonic() + timeout_sec
            while not self.server_is_ready():
                if deadline is not None and time.monotonic() >= deadline:
                    return False
                time.sleep(0.01)
            return True
        return bool(ctx.run_sync(_actions.ActionClient.wait_for_server(self, timeout_sec), "ActionClient.wait_for_server"))

    def send_goal_async(self, goal: Any, feedback_callback: Any = None, goal_uuid: Any = None) -> Any:
        ctx = self.node._context
        from ...._core._future import future_of

        if not isinstance(goal, self.action_type.Goal):
            raise TypeError(f"send_goal_async expects {self.action_type.Goal.__msgtype__}, got {type(goal).__name__}")
        coro = _actions.ActionClient.send_goal(self, goal, _wrap(self.node, feedback_callback), goal_uuid=goal_uuid)
        fut = future_of(coro, self._loop_for_futures())
        fut.add_done_callback(lambda _f: ctx.callback_finished())
        return fut

    def send_goal(self, goal: Any, **kwargs: Any) -> Any:  # type: ignore[override]
        """Block until the goal's result; the ``GetResult`` response (``.status``, ``.result``)."""

        async def run() -> Any:
            handle = await _actions.ActionClient.send_goal(self, goal, _wrap(self.node, kwargs.get("feedback_callback")))
            if not handle.accepted:
                return None
            return await handle._result_response()

        return self.node._context.run_sync(run(), "ActionClient.send_goal")


class AsyncActionClient(ActionClient):
    """An action client of an AsyncNode: its calls are awaited on the program's loop.

    ``await wait_for_server()``, ``await send_goal_async(goal, feedback_callback)`` (the goal
    handle), ``await handle.get_result_async()`` / ``cancel_goal_async()``, and
    ``await send_goal(goal)`` (the ``GetResult`` response); feedback callbacks run on the
    program's loop, as the node's other callbacks.
    """

    def _loop_for_futures(self) -> Any:
        return self.node._context.loop  # the work runs on the context's loop; the futures are awaited anywhere

    async def wait_for_server(self, timeout_sec: float | None = None) -> bool:  # type: ignore[override]
        import asyncio

        loop = self._loop_for_futures()
        if loop is None:
            raise RuntimeError("ActionClient.wait_for_server: the context was shut down")
        waiting = asyncio.run_coroutine_threadsafe(_actions.ActionClient.wait_for_server(self, timeout_sec), loop)
        return bool(await asyncio.wrap_future(waiting))

    async def send_goal(self, goal: Any, **kwargs: Any) -> Any:  # type: ignore[override]
        handle = await self.send_goal_async(goal, kwargs.get("feedback_callback"), kwargs.get("goal_uuid"))
        if not handle.accepted:
            return None
        return await handle.get_result_async()


_orig_get_result_async = ClientGoalHandle.get_result_async

__getattr__ = module_getattr(__name__, "rclpy.action", {"get_action_client_names_and_types_by_node",
                                                         "get_action_names_and_types",
                                                         "get_action_server_names_and_types_by_node"})
