"""``aiorobot.lowlevel`` and the public seams beside it: what extensions use instead of the core's privates."""

from __future__ import annotations

import asyncio
import importlib.util
import os
import signal
import subprocess
import sys
import textwrap
from pathlib import Path
from typing import Any

import pytest

import aiorobot
import aiorobot.testing
from aiorobot import Node, QoSProfile, Runtime
from aiorobot import lowlevel
from aiorobot.msgs.example_interfaces import AddTwoInts
from aiorobot.msgs.std_msgs import Int32, String

ROOT = Path(__file__).resolve().parents[2]


def test_every_name_in_all_is_there_and_documented():
    for name in lowlevel.__all__:
        obj = getattr(lowlevel, name)
        assert name == "ON_FAILURE" or (obj.__doc__ or "").strip(), name


def test_the_test_kit_re_exports_the_core_settle_and_wait_for_message():
    assert aiorobot.testing.settle is Runtime.settle
    assert aiorobot.testing.wait_for_message is lowlevel.wait_for_message


async def test_a_tap_sees_every_message_until_removed():
    got: list[int] = []
    async with Runtime(handle_signals=False) as rt:
        node = rt.add_node(Node("talker"))
        pub = node.create_publisher(Int32, "/n", 10)
        tap = lowlevel.Tap(Int32, "/n", QoSProfile(depth=10), lambda m: got.append(m.data), owner="test")
        lowlevel.add_tap(rt, tap)
        assert pub.get_subscription_count() == 1
        for i in range(3):
            pub.publish(Int32(data=i))
        lowlevel.remove_tap(rt, tap)
        pub.publish(Int32(data=99))
        lowlevel.remove_tap(rt, tap)  # removing twice does nothing
    assert got == [0, 1, 2]


async def test_watch_publishers_reports_existing_then_new_ones_until_unwatched():
    seen: list[str] = []
    async with Runtime(handle_signals=False) as rt:
        node = rt.add_node(Node("n"))
        node.create_publisher(String, "/before", 10)
        node.create_subscription(String, "/subscribed_only", lambda m: None, 10)
        unwatch = lowlevel.watch_publishers(rt, lambda pub: seen.append(pub.topic_name))
        assert seen == ["/before", "/parameter_events", "/rosout"]  # the publishers already there, not subscriptions
        node.create_publisher(String, "/after", 10)
        assert seen[3:] == ["/after"]  # reported before create_publisher returned
        unwatch()
        node.create_publisher(String, "/unwatched", 10)
        new_only = lowlevel.watch_publishers(rt, lambda pub: seen.append("new " + pub.topic_name), existing=False)
        new_only()
    assert seen == ["/before", "/parameter_events", "/rosout", "/after"]


async def test_create_task_belongs_to_the_node_and_ends_with_it():
    node = Node("owner")
    coro = asyncio.sleep(10)
    with pytest.raises(RuntimeError, match=r"^create_task: <Node /owner \(not added\)> is not added to a runtime; "):
        node.create_task(coro)
    async with Runtime(handle_signals=False) as rt:
        rt.add_node(node)
        started = asyncio.Event()

        async def forever() -> None:
            started.set()
            await asyncio.sleep(3600)

        task = node.create_task(forever(), name="forever")
        await started.wait()
        rt.remove_node(node)
        await asyncio.wait_for(asyncio.shield(asyncio.gather(task, return_exceptions=True)), 10)
    assert task.cancelled()


async def test_settle_runs_what_is_queued_on_both_loops():
    got: list[int] = []
    async with Runtime(handle_signals=False) as rt:
        talker = rt.add_node(Node("talker"))
        rt.add_node(Node("listener"), executor="priority").create_subscription(Int32, "/n", lambda m: got.append(m.data), 10)
        pub = talker.create_publisher(Int32, "/n", 10)
        await rt.settle()
        for i in range(5):
            pub.publish(Int32(data=i))
        await rt.settle()
        assert got == [0, 1, 2, 3, 4]


async def test_wait_for_message_returns_the_next_one_or_says_what_it_waited_for():
    async with Runtime(handle_signals=False) as rt:
        probe = rt.add_node(Node("probe"))
        pub = rt.add_node(Node("talker")).create_publisher(String, "/chatter", 10)
        waiting = asyncio.ensure_future(lowlevel.wait_for_message(probe, String, "chatter", timeout_sec=10))
        await rt.settle()
        pub.publish(String(data="hi"))
        assert (await waiting).data == "hi"
        with pytest.raises(TimeoutError, match=r"^no std_msgs/msg/String on /quiet within 0.01 s$"):
            await lowlevel.wait_for_message(probe, String, "/quiet", timeout_sec=0.01)


async def test_on_added_runs_before_the_nodes_endpoints_join_and_a_failure_leaves_it_out():
    order: list[str] = []

    class Watcher(Node):
        def on_added(self) -> None:
            order.append(f"added, runtime has {len(self.runtime.graph.topics)} topics")
            self.unwatch = lowlevel.watch_publishers(self.runtime, lambda p: order.append(p.topic_name))

    class Broken(Node):
        def on_added(self) -> None:
            raise OSError("port taken")

    async with Runtime(handle_signals=False) as rt:
        talker = Node("talker")
        talker.create_publisher(String, "/chatter", 10)
        rt.add_node(Watcher("watcher"))
        rt.add_node(talker)
        # the watcher's own publisher joins after on_added, the talker's after it: all seen
        assert order == [
            "added, runtime has 0 topics", "/parameter_events", "/rosout", "/parameter_events", "/rosout", "/chatter",
        ]
        broken = Broken("broken")
        with pytest.raises(OSError, match="^port taken$"):
            rt.add_node(broken)
        assert broken not in rt.nodes and broken.executor is None
        assert "/broken" not in {n.fully_qualified_name for n in rt.graph.nodes}


async def test_add_client_makes_an_extensions_client_the_nodes_own():
    class LoudClient(aiorobot.Client):
        pass

    async with Runtime(handle_signals=False) as rt:
        rt.add_node(Node("server")).create_service(AddTwoInts, "/add", lambda r: AddTwoInts.Response(sum=r.a + r.b))
        node = rt.add_node(Node("caller"))
        client = lowlevel.add_client(node, LoudClient(node, AddTwoInts, "/add", node.default_callback_group))
        assert node.clients == (client,)
        assert await client.wait_for_service(timeout_sec=10)
        assert (await client.call(AddTwoInts.Request(a=2, b=3))).sum == 5
        other = Node("other")
        with pytest.raises(ValueError, match=r"^add_client: .* was built for <Node /caller on main>, not <Node /other \(not added\)>$"):
            lowlevel.add_client(other, client)


async def test_set_on_failure_continue_keeps_the_run_going_and_a_bad_policy_is_named():
    class Failing(Node):
        async def on_start(self) -> None:
            raise ValueError("no device")

    node = Failing("failing")
    with pytest.raises(ValueError, match=r"^on_failure: expected one of stop, continue, restart, found 'halt'$"):
        lowlevel.set_on_failure(node, "halt")
    lowlevel.set_on_failure(node, "continue")
    async with Runtime(handle_signals=False) as rt:
        rt.add_node(node)
        await rt.settle()
        for _ in range(1000):  # on_start runs as a task: poll, bounded
            if rt.statistics()["failed_starts"]:
                break
            await asyncio.sleep(0.01)
        assert rt.statistics()["failed_starts"] == ["/failing"]
        assert not rt.is_shutdown


def test_node_loop_is_none_until_added():
    assert lowlevel.node_loop(Node("alone")) is None


EMERGENCY = textwrap.dedent(
    """
    import sys, threading
    import aiorobot
    from aiorobot import Node, Runtime
    from aiorobot.lowlevel import add_emergency_stop

    released = threading.Event()

    def emergency_stop():
        print("emergency stop while the loop is blocked", flush=True)
        released.set()

    class Stuck(Node):
        async def on_start(self):
            add_emergency_stop(self.runtime, "stuck", emergency_stop)
            self.create_timer(0.01, self.block)

        def block(self):
            print("blocking", flush=True)
            released.wait(30)

    async def main():
        async with Runtime() as rt:
            rt.add_node(Stuck("stuck"))
            await rt.spin()
        print("clean exit", flush=True)

    if __name__ == "__main__":
        aiorobot.run(main())
    """
)


def test_an_emergency_stop_runs_on_sigint_while_a_callback_blocks_the_loop(tmp_path):
    script = tmp_path / "stuck.py"
    script.write_text(EMERGENCY)
    proc = subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env={**os.environ, "PYTHONWARNINGS": "error"})
    try:
        assert proc.stdout is not None and proc.stdout.readline().strip() == "blocking"
        proc.send_signal(signal.SIGINT)
        out, err = proc.communicate(timeout=30)
    finally:
        proc.kill()
    assert out.splitlines()[0] == "emergency stop while the loop is blocked", err
    assert out.splitlines()[-1] == "clean exit" and proc.returncode == 0, err


def _private_reaches() -> Any:
    spec = importlib.util.spec_from_file_location("private_reaches", ROOT / "tools" / "private_reaches.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


#: the reaches left, each with its reason (issue #28 allows at most 5)
ALLOWED_REACHES = {
    # rclpy's LifecycleNode: on_shutdown(state) is a transition callback, so the compat node keeps
    # the runtime's on_shutdown hook from running it
    ("aiorobot/compat/rclpy/lifecycle/node.py", "super()._run_hook"),
}


def test_extensions_do_not_reach_into_private_members_of_runtime_or_node():
    found = {(path, text) for path, _, text in _private_reaches().reaches(ROOT)}
    assert found <= ALLOWED_REACHES, f"use aiorobot.lowlevel or a public method instead: {sorted(found - ALLOWED_REACHES)}"
    assert len(ALLOWED_REACHES) <= 5


def test_the_reach_counter_finds_a_reach(tmp_path):
    for package in _private_reaches().EXTENSIONS:
        (tmp_path / package).mkdir(parents=True)
    (tmp_path / "aiorobot" / "_node.py").write_text("class Node:\n    def __init__(self):\n        self._loop = None\n")
    for name, cls in (("_runtime.py", "Runtime"), ("_node_parameters.py", "NodeParametersMixin"), ("_node_graph.py", "NodeGraphMixin")):
        (tmp_path / "aiorobot" / name).write_text(f"class {cls}:\n    pass\n")
    (tmp_path / "control" / "x.py").write_text(
        "class Own:\n    def f(self):\n        self._loop = 1\n        return self._loop\n"
        "def g(node, loop):\n    return node._loop, loop._loop\n"
    )
    found = list(_private_reaches().reaches(tmp_path))
    assert found == [("control/x.py", 6, "node._loop")]
