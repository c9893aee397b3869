"""ROS 2's lifecycle demo, ported: a managed talker and a manager driving it through its services.

The talker (``lc_talker``) creates its lifecycle publisher and timer in
``on_configure``; its timer ticks whenever it is configured, but messages reach
``/lifecycle_chatter`` only while it is active. The manager (``lc_service_client``)
walks it through configure, activate, deactivate, activate, deactivate, cleanup
and shutdown with ``~/change_state`` calls, as ``ros2 lifecycle set`` would.

Run it::

    python examples/lifecycle_talker.py
"""

from __future__ import annotations

from typing import Any

import aiorobot
from aiorobot import Node, Runtime
from aiorobot.lifecycle import LifecycleNode, LifecycleState, TransitionCallbackReturn
from aiorobot.msgs.lifecycle_msgs import ChangeState, GetState, Transition
from aiorobot.msgs.std_msgs import String

__all__ = ["LifecycleManager", "LifecycleTalker", "main"]


class LifecycleTalker(LifecycleNode):
    """Publishes ``Lifecycle HelloWorld #n`` on ``lifecycle_chatter`` every ``period_sec`` while active."""

    def __init__(self, **kw: Any) -> None:
        super().__init__("lc_talker", **kw)
        self.period_sec = self.declare_parameter(
            "period_sec", 1.0, description="time between messages", range=(0.001, 60.0)
        ).value
        self.count = 0
        self.pub: Any = None
        self.timer: Any = None

    async def tick(self) -> None:
        self.count += 1
        msg = String(data=f"Lifecycle HelloWorld #{self.count}")
        if self.pub.is_activated:
            self.get_logger().info(f"Lifecycle publisher is active. Publishing: [{msg.data}]")
        else:
            self.get_logger().info("Lifecycle publisher is currently inactive. Messages are not published.")
        self.pub.publish(msg)  # dropped unless active

    async def on_configure(self, state: LifecycleState) -> TransitionCallbackReturn:
        self.pub = self.create_lifecycle_publisher(String, "lifecycle_chatter", 10)
        self.timer = self.create_timer(self.period_sec, self.tick)
        self.get_logger().info(f"on_configure() is called from state {state.label}")
        return TransitionCallbackReturn.SUCCESS

    async def on_activate(self, state: LifecycleState) -> TransitionCallbackReturn:
        self.get_logger().info(f"on_activate() is called from state {state.label}")
        return TransitionCallbackReturn.SUCCESS

    async def on_deactivate(self, state: LifecycleState) -> TransitionCallbackReturn:
        self.get_logger().info(f"on_deactivate() is called from state {state.label}")
        return TransitionCallbackReturn.SUCCESS

    def _release(self) -> None:
        if self.timer is not None:
            self.destroy_timer(self.timer)
            self.timer = None
        if self.pub is not None:
            self.pub.destroy()
            self.pub = None

    async def on_cleanup(self, state: LifecycleState) -> TransitionCallbackReturn:
        self._release()
        self.get_logger().info(f"on_cleanup() is called from state {state.label}")
        return TransitionCallbackReturn.SUCCESS

    async def on_shutdown_transition(self, state: LifecycleState) -> TransitionCallbackReturn:
        self._release()
        self.get_logger().info(f"on_shutdown() is called from state {state.label}")
        return TransitionCallbackReturn.SUCCESS


class LifecycleManager(Node):
    """Drives the node ``target`` through its lifecycle over ``~/change_state``, holding each state ``hold_sec``."""

    SEQUENCE = ("configure", "activate", "deactivate", "activate", "deactivate", "cleanup", "shutdown")

    def __init__(self, target: str = "lc_talker", *, hold_sec: float = 2.0, **kw: Any) -> None:
        super().__init__("lc_service_client", **kw)
        self.hold_sec = hold_sec
        self.change = self.create_client(ChangeState, f"/{target}/change_state")
        self.get_state = self.create_client(GetState, f"/{target}/get_state")
        self.states_seen: list[str] = []

    async def change_state(self, label: str) -> bool:
        request = ChangeState.Request(transition=Transition(label=label))
        ok = bool((await self.change.call(request, timeout_sec=10.0)).success)
        self.get_logger().info(f"Transition {label} {'successfully triggered' if ok else 'failed'}")
        return ok

    async def current_state(self) -> str:
        state = (await self.get_state.call(GetState.Request(), timeout_sec=10.0)).current_state
        self.get_logger().info(f"Node has current state {state.label}")
        return str(state.label)

    async def run_demo(self) -> None:
        if not await self.change.wait_for_service(timeout_sec=10.0):
            raise RuntimeError(f"{self.change.srv_name} is not available; is the talker running?")
        for label in self.SEQUENCE:
            if not await self.change_state(label):
                raise RuntimeError(f"transition {label!r} failed")
            self.states_seen.append(await self.current_state())
            if label in ("activate", "deactivate"):
                await self.get_clock().sleep_for(self.hold_sec)


async def main() -> None:
    async with Runtime() as rt:
        rt.add_node(LifecycleTalker(parameter_overrides={"period_sec": 0.5}))
        listener = rt.add_node(Node("listener"))
        listener.create_subscription(
            String, "lifecycle_chatter", lambda m: listener.get_logger().info(f"I heard: [{m.data}]"), 10
        )
        manager = rt.add_node(LifecycleManager(hold_sec=2.0))
        await manager.run_demo()


if __name__ == "__main__":
    aiorobot.setup_logging()
    aiorobot.run(main())
