"""``aiorobot top``: every node of a two-process graph, from the runtimes' own statistics."""

from __future__ import annotations

import asyncio
import json
import sys

from tests.transport._helpers import spawn

PROCESS = """
import threading, time
from aiorobot.msgs.std_msgs import String
NAME = {name!r}

def crunch():  # the left process: a thread making GIL-holding C calls of about 4 ms
    start = time.perf_counter()
    sum(range(100_000))
    n = max(10_000, int(100_000 * 0.004 / max(time.perf_counter() - start, 1e-6)))
    while True:
        sum(range(n))
        time.sleep(0.003)

async def main(rt):
    control = Node(NAME + "_control")
    pub = control.create_publisher(String, "/" + NAME + "/state", 10)
    control.create_timer(0.01, lambda: pub.publish(String(data="ok")))
    rt.add_node(control, "priority")
    watcher = rt.add_node(Node(NAME + "_watcher", namespace="/robot"))
    watcher.create_subscription(String, "/" + NAME + "/state", lambda m: None, 10)
    if NAME == "left":
        threading.Thread(target=crunch, daemon=True).start()
        while sum(c.late_periods for c in rt.statistics()["culprits"] if c.function == "crunch") < 6:
            await asyncio.sleep(0.05)
    say("ready")
    await asyncio.Event().wait()
"""


async def _top(port: int, *argv: str) -> tuple[int, str, str]:
    proc = await asyncio.create_subprocess_exec(
        sys.executable, "-m", "aiorobot.cli", "top", *argv, "--connect", f"tcp/127.0.0.1:{port}",
        stdout=asyncio.subprocess.PIPE, stderr=asyncio.subprocess.PIPE,
    )
    out, err = await asyncio.wait_for(proc.communicate(), 40)
    return proc.returncode or 0, out.decode(), err.decode()


async def test_top_once_json_lists_every_node_of_two_processes(router_port: int) -> None:
    children = [await spawn(PROCESS.format(name=name), router_port) for name in ("left", "right")]
    try:
        for child in children:
            await child.expect("ready")
        code, out, err = await _top(router_port, "--once", "--json", "--interval", "0.5")
        assert code == 0, err
        report = json.loads(out)
        assert [n["name"] for n in report["nodes"]] == [
            "/left_control", "/right_control", "/robot/left_watcher", "/robot/right_watcher",
        ]
        pids = {child.proc.pid for child in children}
        assert {p["pid"] for p in report["processes"]} == pids
        assert all(len(p["nodes"]) == 2 and p["cpu_percent"] >= 0 for p in report["processes"])
        for node in report["nodes"]:
            assert node["pid"] in pids
            if node["name"].endswith("_control"):
                (timer,) = [e for e in node["entities"] if e["kind"] == "timer"]
                assert node["executor"] == "priority" and timer["name"] == "0.01s"
                assert timer["callbacks"] > 0 and timer["callbacks_per_sec"] > 0
            else:
                (sub,) = [e for e in node["entities"] if e["kind"] == "subscription"]
                assert sub["received"] > 0 and sub["dropped"] == 0 and sub["depth"] == 10
        topics = {t["topic"]: t for t in report["topics"]}
        assert topics["/left/state"]["out_per_sec"] > 0 and topics["/left/state"]["in_per_sec"] > 0
        assert report["without_statistics"] == []
        # the culprit of the left process's late periods, named from the other process
        left = next(p for p in report["processes"] if p["pid"] == children[0].proc.pid)
        named = [c for c in left["culprits"] if not c["function"].startswith("(")]
        assert named[0]["function"] == "crunch" and named[0]["late_periods"] >= 6, left["culprits"]
        assert named[0]["where"].startswith("<string>:") and left["late_periods"] >= 6

        code, out, err = await _top(router_port, "--once", "--interval", "0.2")
        assert code == 0, err
        assert "/robot/left_watcher" in out and "subscription /right/state" in out and "timer 0.01s" in out
    finally:
        for child in children:
            await child.stop()


async def test_top_says_so_when_the_graph_is_empty(router_port: int) -> None:
    code, out, err = await _top(router_port, "--once", "--json", "--interval", "0.1")
    assert code == 1
    assert err.startswith("aiorobot top: no node found in the graph")
    assert json.loads(out)["nodes"] == []


async def test_top_refuses_json_without_once() -> None:
    proc = await asyncio.create_subprocess_exec(
        sys.executable, "-m", "aiorobot.cli", "top", "--json", stdout=asyncio.subprocess.PIPE, stderr=asyncio.subprocess.PIPE,
    )
    _, err = await asyncio.wait_for(proc.communicate(), 30)
    assert proc.returncode == 2
    assert err.decode() == "aiorobot top: error: --json needs --once (the live table is for a terminal)\n"
