"""``rclpy.wait_for_message``: block until the next message on a topic, as rclpy's."""

from __future__ import annotations

from typing import Any

from ..._core._groups import ReentrantCallbackGroup
from ..._core._qos import QoSProfile
from .._node import raw

__all__ = ["wait_for_message"]


def wait_for_message(
    msg_type: Any, node: Any, topic: str, *, qos_profile: QoSProfile | int = 1, time_to_wait: float = -1
) -> tuple[bool, Any]:
    """``(True, msg)`` with the next message on ``topic``, or ``(False, None)`` after ``time_to_wait``
    seconds (negative: no limit) or when the context shuts down, as rclpy's.

    As rclpy's wait set, it waits for this subscription only: the program's callbacks do
    not run meanwhile (they wait for the next spin); aiorobot's own work (message delivery,
    services' plumbing) does.
    """
    ctx = node.context
    got: list[Any] = []
    with raw(node):  # its own group: the node's may be held by a callback waiting for the next spin
        sub = node.create_subscription(
            msg_type, topic, lambda msg: (got.append(msg), ctx.wake()), qos_profile,
            callback_group=ReentrantCallbackGroup(),
        )
    try:
        timeout = None if time_to_wait is None or time_to_wait < 0 else float(time_to_wait)
        ctx.spin_until(None, lambda: bool(got), timeout, raise_on_shutdown=False, admissions=0)
        if got:
            return True, got[0]
        return False, None
    finally:
        node.destroy_subscription(sub)
