"""The priority loop: its own thread, cross-loop delivery both ways, timers there."""

import asyncio
import threading

from aiorobot import Node
from aiorobot.msgs.std_msgs import Int32
from aiorobot.testing import settle, wait_for_message


class Echo(Node):
    """Republishes /in on /out and records which thread ran the callback."""

    def __init__(self, **kw):
        super().__init__("echo", **kw)
        self.threads = set()
        self.seen = []
        self.pub = self.create_publisher(Int32, "/out", 10)
        self.create_subscription(Int32, "/in", self.on_in, 10)

    def on_in(self, msg):
        self.threads.add(threading.get_ident())
        self.seen.append(msg)
        self.pub.publish(msg)


async def test_priority_node_runs_on_its_own_thread_and_messages_cross_both_ways(runtime):
    echo = runtime.add_node(Echo(), executor="priority")
    main = runtime.add_node(Node("main"))
    pub = main.create_publisher(Int32, "/in", 10)
    stream = main.subscribe(Int32, "/out", 10)
    msg = Int32(data=7)
    pub.publish(msg)
    back = await asyncio.wait_for(anext(stream), 30)
    assert back == msg and back is not echo.seen[0]  # each publish hands on its own copy
    assert echo.seen == [msg]
    assert echo.threads == {runtime.priority_loop.thread_id}
    assert runtime.priority_loop.thread_id != threading.get_ident()
    assert echo.executor == "priority" and main.executor == "main"
    stream.close()


async def test_many_messages_cross_in_order(runtime):
    echo = runtime.add_node(Echo(), executor="priority")
    main = runtime.add_node(Node("main"))
    pub = main.create_publisher(Int32, "/in", 1000)
    for i in range(500):
        pub.publish(Int32(data=i))
    await settle(runtime)
    assert [m.data for m in echo.seen][-10:] == list(range(490, 500))
    assert [m.data for m in echo.seen] == sorted(m.data for m in echo.seen)


async def test_timer_on_priority_loop_fires_there(runtime):
    fired = threading.Event()
    threads = []

    class Tick(Node):
        def __init__(self):
            super().__init__("tick")
            self.pub = self.create_publisher(Int32, "/tick", 10)
            self.create_timer(0.002, self.on_timer)

        def on_timer(self):
            threads.append(threading.get_ident())
            self.pub.publish(Int32(data=len(threads)))

    runtime.add_node(Tick(), executor="priority")
    probe = runtime.add_node(Node("probe"))
    await wait_for_message(probe, Int32, "/tick", timeout_sec=30)
    assert set(threads) == {runtime.priority_loop.thread_id}
    del fired


async def test_publish_from_a_foreign_thread_reaches_both_loops(runtime):
    prio = runtime.add_node(Node("prio"), executor="priority")
    main = runtime.add_node(Node("main"))
    got_prio = []
    prio.create_subscription(Int32, "/x", got_prio.append, 10)
    stream = main.subscribe(Int32, "/x", 10)
    pub = main.create_publisher(Int32, "/x", 10)
    await runtime.add_node(Node("worker")).run_in_thread(pub.publish, Int32(data=3))
    assert (await asyncio.wait_for(anext(stream), 30)).data == 3
    await settle(runtime)
    assert [m.data for m in got_prio] == [3]
    stream.close()


async def test_no_priority_thread_unless_asked(runtime):
    runtime.add_node(Node("n"))
    assert runtime.priority_loop is None
