"""Native aiorobot nodes for the quality_of_service_demo programs (``aiorobot exec --node tests.compat.qos_nodes:X``)."""

from __future__ import annotations

import aiorobot
from aiorobot.msgs.sensor_msgs import Image
from aiorobot.msgs.std_msgs import String

__all__ = ["BigImageTalker", "QosOverridesProbe"]


class BigImageTalker(aiorobot.Node):
    """message_lost_talker's part: bursts of 8 MiB images, faster than a depth-1 listener takes them."""

    def __init__(self) -> None:
        super().__init__("message_lost_talker")
        self.pub = self.create_publisher(Image, "/message_lost_chatter", 1)
        self.data = bytes(8 * 1024 * 1024)
        self.sent = 0
        self.create_timer(0.5, self.burst)

    async def burst(self) -> None:
        if not self.pub.get_subscription_count():
            return
        for _ in range(3):  # back to back: the listener's one-slot queue keeps only the newest
            msg = Image(height=1024, width=8192, encoding="mono8", step=8192, data=self.data)
            msg.header.stamp = self.get_clock().now().to_msg()
            self.pub.publish(msg)
            self.sent += 1
        print(f"native talker sent {self.sent} images", flush=True)


class QosOverridesProbe(aiorobot.Node):
    """Prints the QoS the program's endpoints on /qos_overrides_chatter got, once they exist."""

    def __init__(self) -> None:
        super().__init__("qos_probe")
        self.create_subscription(String, "/qos_overrides_chatter", self.on_msg, 10)
        self.pub = self.create_publisher(String, "/qos_overrides_chatter", 10)
        self.create_timer(0.2, self.look)
        self.seen: set[str] = set()
        self.count = 0

    async def on_msg(self, msg: String) -> None:
        if not msg.data.startswith("native"):
            print(f"native heard: {msg.data}", flush=True)

    async def look(self) -> None:
        self.pub.publish(String(data=f"native {self.count}"))
        self.count += 1
        graph = self._runtime.graph  # type: ignore[union-attr]
        for info in graph.publishers_of("/qos_overrides_chatter") + graph.subscriptions_of("/qos_overrides_chatter"):
            if info.node.lstrip("/") != "qos_probe" and info.kind not in self.seen:
                self.seen.add(info.kind)
                print(f"native sees {info.kind} of {info.node}: {info.qos.short()}", flush=True)
