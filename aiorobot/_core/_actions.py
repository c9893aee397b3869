"""Actions, built as ROS 2 builds them: three services and two topics under ``<action>/_action/``.

* ``send_goal`` (``X.SendGoal``), ``cancel_goal`` (``action_msgs/srv/CancelGoal``),
  ``get_result`` (``X.GetResult``) services;
* ``feedback`` (``X.FeedbackMessage``) and ``status`` (``action_msgs/msg/GoalStatusArray``,
  transient local) topics.

So a transport that maps services and topics (rmw_zenoh's way) carries actions
without knowing about them. Goal ids are random UUIDs (``unique_identifier_msgs/UUID``).
"""

from __future__ import annotations

import asyncio
import enum
import functools
import inspect
import uuid
from collections import deque
from collections.abc import AsyncIterator, Callable
from typing import TYPE_CHECKING, Any

from ._future import Future, future_of
from ._groups import CallbackGroup, MutuallyExclusiveCallbackGroup, ReentrantCallbackGroup
from ._qos import DurabilityPolicy, QoSProfile
from ._services import ServiceUnavailableError, after_reply

if TYPE_CHECKING:
    from ._node import Node

__all__ = [
    "ActionClient",
    "ActionServer",
    "CancelResponse",
    "ClientGoalHandle",
    "GoalResponse",
    "GoalStatus",
    "ServerGoalHandle",
]

STATUS_QOS = QoSProfile(durability=DurabilityPolicy.TRANSIENT_LOCAL, depth=1)
FEEDBACK_QOS = QoSProfile(depth=10)
#: Finished goals whose results a server keeps for late ``get_result`` calls.
MAX_KEPT_RESULTS = 256
#: How long a server keeps a finished goal's result (rclpy's ``result_timeout`` default).
DEFAULT_RESULT_TIMEOUT_SEC = 10.0


class GoalStatus(enum.IntEnum):
    """``action_msgs/msg/GoalStatus`` values."""

    UNKNOWN = 0
    ACCEPTED = 1
    EXECUTING = 2
    CANCELING = 3
    SUCCEEDED = 4
    CANCELED = 5
    ABORTED = 6

    @property
    def is_terminal(self) -> bool:
        return self in (GoalStatus.SUCCEEDED, GoalStatus.CANCELED, GoalStatus.ABORTED)


class GoalResponse(enum.IntEnum):
    """What a ``goal_callback`` answers (``True``/``False`` work too)."""

    REJECT = 1
    ACCEPT = 2


class CancelResponse(enum.IntEnum):
    """What a ``cancel_callback`` answers (``True``/``False`` work too)."""

    REJECT = 1
    ACCEPT = 2


# CancelGoal return codes (action_msgs/srv/CancelGoal)
_ERROR_NONE, _ERROR_REJECTED, _ERROR_UNKNOWN_GOAL_ID, _ERROR_GOAL_TERMINATED = 0, 1, 2, 3


def _check_action_type(action_type: Any) -> None:
    needed = ("Goal", "Result", "Feedback", "SendGoal", "GetResult", "FeedbackMessage")
    if not (isinstance(action_type, type) and all(hasattr(action_type, n) for n in needed)):
        raise TypeError(
            f"expected an action type with .Goal/.Result/.Feedback (e.g. aiorobot.msgs.example_interfaces.Fibonacci), got {action_type!r}"
        )


def _gid(goal_id: Any) -> bytes:
    return bytes(bytearray(goal_id.uuid))


def _gid_str(goal_id: Any) -> str:
    return str(uuid.UUID(bytes=_gid(goal_id)))


async def _maybe_await(value: Any) -> Any:
    return await value if inspect.isawaitable(value) else value


class ServerGoalHandle:
    """One goal on the server: ``request``, ``publish_feedback``, ``succeed``/``abort``/``canceled``."""

    def __init__(self, server: ActionServer, goal_id: Any, request: Any, stamp: Any) -> None:
        self._server = server
        self.goal_id = goal_id
        self.request = request
        self.stamp = stamp
        self._status = GoalStatus.ACCEPTED
        self._result: Any = None
        self._done: asyncio.Future[None] = server.node._loop.create_future()  # type: ignore[union-attr]
        self._task: asyncio.Task[Any] | None = None

    def __repr__(self) -> str:
        return f"<ServerGoalHandle {_gid_str(self.goal_id)} {self._status.name} of {self._server.name}>"

    @property
    def status(self) -> GoalStatus:
        return self._status

    @property
    def is_active(self) -> bool:
        return not self._status.is_terminal

    @property
    def is_cancel_requested(self) -> bool:
        return self._status is GoalStatus.CANCELING

    def execute(self, execute_callback: Callable[[ServerGoalHandle], Any] | None = None) -> None:
        """Start executing this goal: ``EXECUTING``, then ``execute_callback`` (default: the server's).

        What the default ``handle_accepted_callback`` does at once; a server that
        queues or preempts goals calls it later (as rclpy's ``goal_handle.execute()``).
        A goal whose cancel was requested meanwhile stays ``CANCELING`` and the
        callback still runs, to end it with ``canceled()``.
        """
        if not self.is_active:
            raise RuntimeError(f"{self!r} is finished; it cannot be executed")
        if self._task is not None:
            raise RuntimeError(f"{self!r} is already executing; execute() runs a goal once")
        if self._status is GoalStatus.ACCEPTED:
            self._status = GoalStatus.EXECUTING
            self._server._publish_status()
        server = self._server
        callback = execute_callback or server._execute
        self._task = server.node._create_task(server._run_goal(self, callback), name=f"goal {_gid_str(self.goal_id)}")

    def publish_feedback(self, feedback: Any) -> None:
        action = self._server.action_type
        if not isinstance(feedback, action.Feedback):
            raise TypeError(f"publish_feedback expects {action.Feedback.__msgtype__}, got {type(feedback).__name__}")
        if not self.is_active:
            raise RuntimeError(f"{self!r} is finished; it cannot publish feedback")
        self._server._feedback_pub.publish(action.FeedbackMessage(goal_id=self.goal_id, feedback=feedback))

    def _transition(self, status: GoalStatus, allowed: tuple[GoalStatus, ...]) -> None:
        if self._status not in allowed:
            raise RuntimeError(
                f"goal {_gid_str(self.goal_id)} cannot become {status.name} from {self._status.name}"
            )
        self._status = status
        self._server._publish_status()
        if status.is_terminal and self._task is None:
            # ended before it ever executed (a queue or preemption server dropping it): its
            # result is the empty Result, so get_result answers instead of waiting forever
            self._server._finish(self, self._server.action_type.Result())

    def succeed(self) -> None:
        self._transition(GoalStatus.SUCCEEDED, (GoalStatus.EXECUTING, GoalStatus.CANCELING))

    def abort(self) -> None:
        self._transition(GoalStatus.ABORTED, (GoalStatus.ACCEPTED, GoalStatus.EXECUTING, GoalStatus.CANCELING))

    def canceled(self) -> None:
        self._transition(GoalStatus.CANCELED, (GoalStatus.CANCELING,))

    def _status_msg(self) -> Any:
        from ..msgs.action_msgs import GoalInfo
        from ..msgs.action_msgs import GoalStatus as GoalStatusMsg

        return GoalStatusMsg(goal_info=GoalInfo(goal_id=self.goal_id, stamp=self.stamp), status=int(self._status))


class ActionServer:
    """Serves an action; created by ``Node.create_action_server``.

    ``execute(goal_handle)`` (async preferred) runs once per accepted goal and returns
    the ``Result``; it sets the outcome with ``goal_handle.succeed()``, ``abort()`` or
    ``canceled()`` — left unset, the goal is aborted with a warning, as in rclpy. An
    ``execute`` that raises aborts that goal only. Goals run concurrently; by default
    they hold no callback-group lock, so a long goal never blocks the node's other
    callbacks (pass ``callback_group`` to serialise them).

    ``handle_accepted_callback(goal_handle)`` is called with each accepted goal once
    the client has its answer; the default calls ``goal_handle.execute()`` at once.
    A server that queues goals, or preempts the running one, passes its own and
    calls ``execute()`` later (rclpy's pattern, as in ros2/examples). A finished
    goal's result is kept for ``result_timeout`` seconds (node clock) for late
    ``get_result`` requests, then forgotten (its status becomes UNKNOWN).

    rclpy difference: ``execute`` holds no callback-group lock unless
    ``callback_group`` is given (rclpy runs it in the server's group, by default
    the node's mutually exclusive one, so one long goal blocks every other
    callback of the node); and a goal ended before it executed (aborted or
    canceled while queued) answers ``get_result`` with the empty ``Result`` where
    rclpy never answers.
    """

    def __init__(
        self,
        node: Node,
        action_type: Any,
        name: str,
        execute: Callable[[ServerGoalHandle], Any],
        *,
        goal_callback: Callable[[Any], Any] | None = None,
        handle_accepted_callback: Callable[[ServerGoalHandle], Any] | None = None,
        cancel_callback: Callable[[ServerGoalHandle], Any] | None = None,
        callback_group: CallbackGroup | None = None,
        result_timeout: float = DEFAULT_RESULT_TIMEOUT_SEC,
    ) -> None:
        _check_action_type(action_type)
        if not callable(execute):
            raise TypeError(f"execute must be callable, got {execute!r}")
        if handle_accepted_callback is not None and not callable(handle_accepted_callback):
            raise TypeError(f"handle_accepted_callback must be callable, got {handle_accepted_callback!r}")
        if isinstance(result_timeout, bool) or not isinstance(result_timeout, (int, float)) or not result_timeout >= 0:
            raise ValueError(f"result_timeout: expected a number of seconds >= 0, got {result_timeout!r}")
        from ..msgs.action_msgs import CancelGoal, GoalStatusArray

        self.node = node
        self.action_type = action_type
        self.name = node.resolve_topic_name(name, kind="action")
        self._execute = execute
        self._goal_callback = goal_callback
        self._handle_accepted_callback = handle_accepted_callback
        self._cancel_callback = cancel_callback
        self.result_timeout = float(result_timeout)
        self._group = callback_group
        self._goals: dict[bytes, ServerGoalHandle] = {}
        self._finished: deque[bytes] = deque()
        self._expiring: deque[tuple[int, bytes, ServerGoalHandle]] = deque()
        self._expiry_wake: asyncio.Future[None] | None = None
        self._expiry_task: asyncio.Task[None] | None = None
        internal = ReentrantCallbackGroup()
        base = self.name + "/_action/"
        self._services = [
            node.create_service(action_type.SendGoal, base + "send_goal", self._on_send_goal, callback_group=internal),
            node.create_service(CancelGoal, base + "cancel_goal", self._on_cancel_goal, callback_group=internal),
            node.create_service(action_type.GetResult, base + "get_result", self._on_get_result, callback_group=internal),
        ]
        # get_result waits for the goal to finish: the goal's own work is what keeps the node busy
        self._services[2].waits_on_others = True
        self._feedback_pub = node.create_publisher(action_type.FeedbackMessage, base + "feedback", FEEDBACK_QOS)
        self._status_pub = node.create_publisher(GoalStatusArray, base + "status", STATUS_QOS)
        self._status_array = GoalStatusArray

    def __repr__(self) -> str:
        active = sum(1 for h in self._goals.values() if h.is_active)
        return f"<ActionServer {self.name} {self.action_type.__msgtype__} active_goals={active}>"

    @property
    def goal_handles(self) -> tuple[ServerGoalHandle, ...]:
        return tuple(self._goals.values())

    def _publish_status(self) -> None:
        self._status_pub.publish(self._status_array(status_list=[h._status_msg() for h in self._goals.values()]))

    async def _on_send_goal(self, request: Any) -> Any:
        action = self.action_type
        stamp = self.node.now().to_msg()
        gid = _gid(request.goal_id)
        accepted = gid not in self._goals
        if accepted and self._goal_callback is not None:
            try:
                verdict = await _maybe_await(self._goal_callback(request.goal))
            except Exception:
                self.node.get_logger().error(f"goal_callback of action {self.name} raised; goal rejected", exc_info=True)
                verdict = GoalResponse.REJECT
            accepted = verdict is True or verdict == GoalResponse.ACCEPT
        if not accepted:
            return action.SendGoal.Response(accepted=False, stamp=stamp)
        if self._expiry_task is None or self._expiry_task.done():
            self._expiry_task = self.node._create_task(self._expire(), name=f"action {self.name} result expiry")
        handle = ServerGoalHandle(self, request.goal_id, request.goal, stamp)
        self._goals[gid] = handle
        self._publish_status()
        # As rclpy: the goal response goes out first, then execute (or handle_accepted_callback)
        # is scheduled. Started before, a plain execute callback that blocks the loop (rclpy
        # programs sleep in theirs) would hold the response back until the goal had finished.
        if not after_reply(functools.partial(self.node._call_soon, self._start, handle)):
            self.node._loop.call_soon(self._start, handle)  # type: ignore[union-attr]  # not from the service
        return action.SendGoal.Response(accepted=True, stamp=stamp)

    def _start(self, handle: ServerGoalHandle) -> None:
        if self._handle_accepted_callback is not None:
            self.node._create_task(self._accepted(handle), name=f"goal {_gid_str(handle.goal_id)} accepted")
        elif handle.is_active and handle._task is None:  # not ended or started meanwhile
            handle.execute()

    async def _accepted(self, handle: ServerGoalHandle) -> None:
        assert self._handle_accepted_callback is not None
        try:
            await _maybe_await(self._handle_accepted_callback(handle))
        except Exception:
            self.node.get_logger().error(
                f"handle_accepted_callback of action {self.name} raised; goal {_gid_str(handle.goal_id)} aborted",
                exc_info=True,
            )
            if handle.is_active:
                handle.abort()

    async def _run_goal(self, handle: ServerGoalHandle, execute: Callable[[ServerGoalHandle], Any]) -> None:
        action = self.action_type
        log = self.node.get_logger()
        result = None
        try:
            if self._group is not None:
                async with self._group:
                    result = await _maybe_await(execute(handle))
            else:
                result = await _maybe_await(execute(handle))
        except asyncio.CancelledError:
            if handle.is_active:
                handle._status = GoalStatus.ABORTED
            self._finish(handle, action.Result())
            raise
        except SystemExit as exc:  # the program ends, as for a callback's; the goal is aborted
            self.node._end_program(exc)
            if handle.is_active:
                handle.abort()
            result = action.Result()
        except Exception:
            log.error(f"execute of action {self.name} raised; goal {_gid_str(handle.goal_id)} aborted", exc_info=True)
            if handle.is_active:
                handle.abort()
            result = action.Result()
        if not isinstance(result, action.Result):
            log.error(
                f"execute of action {self.name} returned {type(result).__name__}, expected {action.Result.__msgtype__}; goal aborted"
            )
            if handle.is_active:
                handle.abort()
            result = action.Result()
        if handle.is_active:
            log.warning(f"goal {_gid_str(handle.goal_id)} of {self.name}: state not set, assuming aborted")
            handle.abort()
        self._finish(handle, result)

    def _finish(self, handle: ServerGoalHandle, result: Any) -> None:
        if handle._done.done():
            return
        handle._result = result
        handle._done.set_result(None)
        gid = _gid(handle.goal_id)
        self._finished.append(gid)
        while len(self._finished) > MAX_KEPT_RESULTS:
            self._goals.pop(self._finished.popleft(), None)
        self._expiring.append((self.node.now().nanoseconds + round(self.result_timeout * 1e9), gid, handle))
        wake = self._expiry_wake
        if wake is not None and not wake.done():
            wake.set_result(None)

    async def _expire(self) -> None:
        """Forget each finished goal ``result_timeout`` seconds (node clock) after it finished.

        One task per server, started with the first goal, so the node's shutdown cancels it
        with its other tasks.
        """
        loop = asyncio.get_running_loop()
        while True:
            if not self._expiring:
                self._expiry_wake = loop.create_future()
                await self._expiry_wake
                continue
            deadline_ns, gid, handle = self._expiring[0]
            remaining_ns = deadline_ns - self.node.now().nanoseconds
            if remaining_ns > 0:
                never: asyncio.Future[None] = loop.create_future()
                try:
                    await self.node._wait_with_timeout(never, remaining_ns / 1e9)
                except TimeoutError:
                    pass
                continue
            self._expiring.popleft()
            if self._goals.get(gid) is handle:
                del self._goals[gid]
                self._publish_status()

    async def _on_get_result(self, request: Any) -> Any:
        handle = self._goals.get(_gid(request.goal_id))
        if handle is None:
            return self.action_type.GetResult.Response(status=int(GoalStatus.UNKNOWN))
        await asyncio.shield(handle._done)
        return self.action_type.GetResult.Response(status=int(handle._status), result=handle._result)

    async def _on_cancel_goal(self, request: Any) -> Any:
        from ..msgs.action_msgs import CancelGoal

        info = request.goal_info
        gid = _gid(info.goal_id)
        stamp_ns = int(info.stamp.sec) * 1_000_000_000 + int(info.stamp.nanosec)
        zero_id = not any(gid)
        candidates: list[ServerGoalHandle] = []
        if not zero_id:
            if gid not in self._goals:
                return CancelGoal.Response(return_code=_ERROR_UNKNOWN_GOAL_ID)
            candidates.append(self._goals[gid])
        if zero_id and stamp_ns == 0:
            candidates = list(self._goals.values())
        elif stamp_ns:
            for h in self._goals.values():
                if int(h.stamp.sec) * 1_000_000_000 + int(h.stamp.nanosec) <= stamp_ns and h not in candidates:
                    candidates.append(h)
        active = [h for h in candidates if h.is_active]
        if not active:
            code = _ERROR_GOAL_TERMINATED if candidates else _ERROR_NONE
            return CancelGoal.Response(return_code=code)
        canceling = []
        for handle in active:
            if handle.is_cancel_requested:
                canceling.append(handle)
                continue
            verdict: Any = CancelResponse.REJECT
            if self._cancel_callback is not None:
                try:
                    verdict = await _maybe_await(self._cancel_callback(handle))
                except Exception:
                    self.node.get_logger().error(f"cancel_callback of action {self.name} raised; cancel rejected", exc_info=True)
            if (verdict is True or verdict == CancelResponse.ACCEPT) and handle.is_active:
                handle._transition(GoalStatus.CANCELING, (GoalStatus.ACCEPTED, GoalStatus.EXECUTING))
                canceling.append(handle)
        if not canceling:
            return CancelGoal.Response(return_code=_ERROR_REJECTED)
        from ..msgs.action_msgs import GoalInfo

        return CancelGoal.Response(
            return_code=_ERROR_NONE,
            goals_canceling=[GoalInfo(goal_id=h.goal_id, stamp=h.stamp) for h in canceling],
        )

    def destroy(self) -> None:
        for service in self._services:
            self.node.destroy_service(service)
        self.node.destroy_publisher(self._feedback_pub)
        self.node.destroy_publisher(self._status_pub)
        for handle in self._goals.values():
            if handle._task is not None:
                handle._task.cancel()


class ClientGoalHandle:
    """A goal sent by an :class:`ActionClient`."""

    def __init__(self, client: ActionClient, goal_id: Any, feedback_callback: Callable[[Any], Any] | None) -> None:
        self._client = client
        self.goal_id = goal_id
        self.accepted = False
        self.stamp: Any = None
        self.status = GoalStatus.UNKNOWN
        self._feedback_callback = feedback_callback
        self._feedback: deque[Any] = deque(maxlen=1000)
        self._feedback_waiter: asyncio.Future[None] | None = None
        self._result: Any = None
        self._result_task: asyncio.Future[Any] | None = None

    def __repr__(self) -> str:
        return f"<ClientGoalHandle {_gid_str(self.goal_id)} {self.status.name} of {self._client.name}>"

    @property
    def goal_id_str(self) -> str:
        return _gid_str(self.goal_id)

    def _on_feedback(self, msg: Any) -> None:
        if self.status.is_terminal:
            return
        self._feedback.append(msg.feedback)
        self._wake()
        if self._feedback_callback is not None:
            node = self._client.node
            node._create_task(
                node._invoke(self._client, ReentrantCallbackGroup(), self._feedback_callback, msg),
                name="feedback callback",
            )

    def _set_status(self, status: GoalStatus) -> None:
        self.status = status
        if status.is_terminal:
            self._wake()

    def _wake(self) -> None:
        waiter = self._feedback_waiter
        if waiter is not None and not waiter.done():
            waiter.set_result(None)

    async def feedback(self) -> AsyncIterator[Any]:
        """``async for fb in handle.feedback()``: the goal's ``Feedback`` messages until it finishes."""
        loop = asyncio.get_running_loop()
        while True:
            while self._feedback:
                yield self._feedback.popleft()
            if self.status.is_terminal:
                return
            self._feedback_waiter = loop.create_future()
            try:
                await self._feedback_waiter
            finally:
                self._feedback_waiter = None

    async def result(self, timeout_sec: float | None = None) -> Any:
        """Wait for the goal to finish and return its ``Result``; ``status`` is then terminal."""
        if self._result_task is None:
            self._result_task = asyncio.ensure_future(self._fetch_result())
        return await self._client.node._wait_with_timeout(asyncio.shield(self._result_task), timeout_sec)

    def get_result_async(self) -> Future[Any]:
        """rclpy's form: a :class:`~aiorobot.Future` of the ``GetResult`` response (``.status``, ``.result``)."""
        return future_of(self._result_response(), self._client._loop_for_futures())

    async def _result_response(self) -> Any:
        result = await self.result()
        return self._client.action_type.GetResult.Response(status=int(self.status), result=result)

    def cancel_goal_async(self) -> Future[Any]:
        """rclpy's form: a :class:`~aiorobot.Future` of the ``action_msgs/srv/CancelGoal`` response."""
        return future_of(self._cancel_response(None), self._client._loop_for_futures())

    async def _cancel_response(self, timeout_sec: float | None) -> Any:
        from ..msgs.action_msgs import CancelGoal, GoalInfo

        return await self._client._cancel_goal.call(
            CancelGoal.Request(goal_info=GoalInfo(goal_id=self.goal_id)), timeout_sec
        )

    async def _fetch_result(self) -> Any:
        action = self._client.action_type
        response = await self._client._get_result.call(action.GetResult.Request(goal_id=self.goal_id))
        self._client._drain_feedback()
        self._result = response.result
        self._set_status(GoalStatus(response.status))
        self._client._handles.pop(_gid(self.goal_id), None)
        return response.result

    async def cancel(self, timeout_sec: float | None = None) -> bool:
        """Ask the server to cancel; True when it accepted (the goal then ends CANCELED, usually)."""
        response = await self._cancel_response(timeout_sec)
        gid = _gid(self.goal_id)
        return response.return_code == _ERROR_NONE and any(_gid(g.goal_id) == gid for g in response.goals_canceling)


class ActionClient:
    """Sends goals to an action server; created by ``Node.create_action_client``.

    ``callback_group`` is kept as in rclpy; feedback, status and results are
    handled in the client's own groups (see :meth:`send_goal`).
    """

    def __init__(self, node: Node, action_type: Any, name: str, *, callback_group: CallbackGroup | None = None) -> None:
        _check_action_type(action_type)
        self.callback_group = callback_group
        from ..msgs.action_msgs import CancelGoal, GoalStatusArray

        self.node = node
        self.action_type = action_type
        self.name = node.resolve_topic_name(name, kind="action")
        base = self.name + "/_action/"
        self._send_goal = node.create_client(action_type.SendGoal, base + "send_goal")
        self._cancel_goal = node.create_client(CancelGoal, base + "cancel_goal")
        self._get_result = node.create_client(action_type.GetResult, base + "get_result")
        # Inline dispatch in one private group keeps feedback and status in publish order
        # (with _drain_feedback); user feedback callbacks still run as tasks of their own.
        group = MutuallyExclusiveCallbackGroup()
        self._handles: dict[bytes, ClientGoalHandle] = {}
        self._feedback_sub = node.create_subscription(
            action_type.FeedbackMessage, base + "feedback", self._on_feedback, FEEDBACK_QOS, callback_group=group
        )
        self._subs = [
            self._feedback_sub,
            node.create_subscription(GoalStatusArray, base + "status", self._on_status, STATUS_QOS, callback_group=group),
        ]

    def __repr__(self) -> str:
        return f"<ActionClient {self.name} {self.action_type.__msgtype__} goals={len(self._handles)}>"

    def _on_feedback(self, msg: Any) -> None:
        handle = self._handles.get(_gid(msg.goal_id))
        if handle is not None:
            handle._on_feedback(msg)

    def _drain_feedback(self) -> None:
        """Handle feedback still queued: it was published before the status or result now arriving."""
        queue = self._feedback_sub._queue
        while queue:
            self._on_feedback(queue.popleft())

    def _on_status(self, msg: Any) -> None:
        self._drain_feedback()
        for st in msg.status_list:
            handle = self._handles.get(_gid(st.goal_info.goal_id))
            if handle is not None and not handle.status.is_terminal:
                handle._set_status(GoalStatus(st.status))

    def server_is_ready(self) -> bool:
        return all(c.service_is_ready() for c in (self._send_goal, self._cancel_goal, self._get_result))

    async def wait_for_server(self, timeout_sec: float | None = None) -> bool:
        for client in (self._send_goal, self._cancel_goal, self._get_result):
            if not await client.wait_for_service(timeout_sec):
                return False
        return True

    def _loop_for_futures(self) -> asyncio.AbstractEventLoop | None:
        try:
            asyncio.get_running_loop()
        except RuntimeError:
            return self.node._loop
        return None

    def send_goal_async(
        self, goal: Any, feedback_callback: Callable[[Any], Any] | None = None, goal_uuid: Any = None
    ) -> Future[ClientGoalHandle]:
        """rclpy's form: a :class:`~aiorobot.Future` of the :class:`ClientGoalHandle` (``.accepted``).

        Then ``goal_handle.get_result_async()`` and ``goal_handle.cancel_goal_async()``.
        ``goal_uuid`` (a ``unique_identifier_msgs/UUID``) fixes the goal id; by default a random one.

        rclpy difference: with no action server the future completes at once with
        ``ServiceUnavailableError`` (rclpy's stays pending forever); await
        ``wait_for_server()`` first, as rclpy's examples do.
        """
        action = self.action_type
        if not isinstance(goal, action.Goal):
            raise TypeError(f"send_goal expects {action.Goal.__msgtype__}, got {type(goal).__name__}")
        return future_of(self.send_goal(goal, feedback_callback, goal_uuid=goal_uuid), self._loop_for_futures())

    async def send_goal(
        self,
        goal: Any,
        feedback_callback: Callable[[Any], Any] | None = None,
        *,
        goal_uuid: Any = None,
        timeout_sec: float | None = None,
    ) -> ClientGoalHandle:
        """Send ``goal``; the handle says whether it was ``accepted``.

        ``feedback_callback(feedback_message)`` gets each ``FeedbackMessage`` (as in rclpy);
        ``handle.feedback()`` yields the inner ``Feedback`` messages.

        rclpy difference: a coroutine (rclpy's ``send_goal`` blocks the thread until
        the goal's result; here ``await handle.result()`` does that part), and
        ``feedback_callback`` may be ``async def``, each call running as a task of its
        own (in a reentrant group), so a slow callback never delays the goal's status,
        result or the next feedback; rclpy runs it in the action client's callback group.
        """
        from ..msgs.unique_identifier_msgs import UUID

        action = self.action_type
        if not isinstance(goal, action.Goal):
            raise TypeError(f"send_goal expects {action.Goal.__msgtype__}, got {type(goal).__name__}")
        if not self._send_goal.service_is_ready():
            raise ServiceUnavailableError(f"no action server for {self.name}; await wait_for_server() first")
        goal_id = goal_uuid if goal_uuid is not None else UUID(uuid=uuid.uuid4().bytes)
        handle = ClientGoalHandle(self, goal_id, feedback_callback)
        gid = _gid(goal_id)
        self._handles[gid] = handle  # before sending: feedback may arrive before the reply
        try:
            response = await self._send_goal.call(action.SendGoal.Request(goal_id=goal_id, goal=goal), timeout_sec)
        except BaseException:
            self._handles.pop(gid, None)
            raise
        handle.accepted = bool(response.accepted)
        handle.stamp = response.stamp
        if handle.accepted:
            if handle.status is GoalStatus.UNKNOWN:
                handle.status = GoalStatus.ACCEPTED
        else:
            self._handles.pop(gid, None)
        return handle

    def destroy(self) -> None:
        for client in (self._send_goal, self._cancel_goal, self._get_result):
            self.node.destroy_client(client)
        for sub in self._subs:
            self.node.destroy_subscription(sub)
