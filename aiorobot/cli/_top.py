"""``aiorobot top``: every node of every process, live: CPU, callbacks, queues, lateness, culprits.

The figures are the runtimes' own (``~/get_statistics`` on every node, see
aiorobot/_core/_stats.py and docs/observability.md), read over the transport, never
sampled from ``ps``. Counts are totals, so a rate needs two readings: ``top`` reads
every node, waits ``--interval`` and reads again; rates are the differences. ``--once``
prints one table (or with ``--json`` one JSON document) after those two readings.
"""

from __future__ import annotations

import argparse
import asyncio
import json
import sys
import time
from typing import Any

from ._graph_session import UserError, add_graph_options, cli_node, join_graph

__all__ = ["add_arguments", "collect", "main", "summarize"]

CALL_TIMEOUT_SEC = 3.0


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--once", action="store_true", help="print one report and exit (two readings --interval apart)")
    parser.add_argument("--json", action="store_true", help="with --once: the report as JSON, for scripts")
    parser.add_argument("--interval", type=float, default=1.0, metavar="SEC",
                        help="seconds between readings (the rates' window; default 1)")
    add_graph_options(parser)


def main(args: argparse.Namespace) -> int:
    from .. import run

    if args.json and not args.once:
        print("aiorobot top: error: --json needs --once (the live table is for a terminal)", file=sys.stderr)
        return 2
    if not args.interval > 0:
        print(f"aiorobot top: error: --interval: expected seconds > 0, found {args.interval:g}", file=sys.stderr)
        return 2
    try:
        return run(_top(args))
    except UserError as err:
        print(f"aiorobot top: error: {err}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        return 0


async def collect(node: Any, names: list[str]) -> tuple[dict[str, dict[str, Any]], list[str]]:
    """Each node's ``~/get_statistics`` document, and the nodes that gave none (no such service)."""
    from ..msgs.std_srvs import Trigger

    async def one(name: str) -> dict[str, Any] | None:
        client = node.create_client(Trigger, f"{name.rstrip('/')}/get_statistics")
        try:
            if not client.service_is_ready():
                return None
            response = await client.call(Trigger.Request(), timeout_sec=CALL_TIMEOUT_SEC)
            doc: dict[str, Any] = json.loads(response.message) if response.success else None
            return doc
        except Exception:  # gone meanwhile, or an answer that is not ours
            return None
        finally:
            node.destroy_client(client)

    answers = await asyncio.gather(*(one(n) for n in names))
    docs = {n: d for n, d in zip(names, answers) if isinstance(d, dict) and "node" in d}
    return docs, [n for n in names if n not in docs]


def _rate(now: float, before: float | None, seconds: float) -> float:
    return round((now - before) / seconds, 2) if before is not None and seconds > 0 else 0.0


def summarize(first: dict[str, dict[str, Any]], second: dict[str, dict[str, Any]], silent: list[str]) -> dict[str, Any]:
    """The report: processes (CPU %, culprits), nodes (entities with rates) and topics (msgs/s)."""
    processes: dict[str, dict[str, Any]] = {}
    nodes = []
    topics: dict[str, dict[str, float]] = {}
    for name, doc in sorted(second.items()):
        proc, node = doc["process"], doc["node"]
        old = first.get(name)
        seconds = proc["monotonic_sec"] - old["process"]["monotonic_sec"] if old else 0.0
        key = f"{proc['host']}:{proc['pid']}"
        if key not in processes:
            cpu = _rate(proc["cpu_sec"], old["process"]["cpu_sec"] if old else None, seconds)
            processes[key] = {
                "pid": proc["pid"], "host": proc["host"], "cpu_percent": round(cpu * 100, 1),
                "threads": proc["threads"], "late_periods": proc["late_periods"],
                "late_threshold_ms": proc["late_threshold_ms"], "culprits": proc["culprits"], "nodes": [],
            }
        processes[key]["nodes"].append(name)
        before = {(e["kind"], e["name"]): e for e in old["node"]["entities"]} if old else {}
        entities = []
        for e in node["entities"]:
            prev = before.get((e["kind"], e["name"]))
            entity = {**e, "callbacks_per_sec": _rate(e["callbacks"], prev["callbacks"] if prev else None, seconds)}
            if e["kind"] == "subscription":
                rate = _rate(e["received"], prev["received"] if prev else None, seconds)
                topics.setdefault(e["name"], {"in_per_sec": 0.0, "out_per_sec": 0.0})["in_per_sec"] += rate
            entities.append(entity)
        old_pubs = {p["topic"]: p for p in old["node"]["publishers"]} if old else {}
        for p in node["publishers"]:
            prev = old_pubs.get(p["topic"])
            rate = _rate(p["published"], prev["published"] if prev else None, seconds)
            topics.setdefault(p["topic"], {"in_per_sec": 0.0, "out_per_sec": 0.0})["out_per_sec"] += rate
        nodes.append({
            "name": name, "pid": proc["pid"], "host": proc["host"], "executor": node["executor"],
            "stalls": node["stalls"], "failures": node["failures"], "entities": entities,
            "publishers": node["publishers"],
        })
    return {
        "processes": list(processes.values()),
        "nodes": nodes,
        "topics": [{"topic": t, **{k: round(v, 2) for k, v in r.items()}} for t, r in sorted(topics.items())],
        "without_statistics": sorted(silent),
    }


async def _reading(rt: Any, node: Any) -> tuple[dict[str, dict[str, Any]], list[str]]:
    own = {n.get_fully_qualified_name() for n in rt.nodes}
    names = sorted({n.fully_qualified_name for n in rt.graph.nodes} - own)
    return await collect(node, names)


async def _top(args: argparse.Namespace) -> int:
    async with join_graph(args) as rt:
        node = cli_node(rt, "aiorobot_top")
        first, _ = await _reading(rt, node)
        if args.once:
            await asyncio.sleep(args.interval)
            second, silent = await _reading(rt, node)
            report = summarize(first, second, silent)
            if not report["nodes"] and not silent:
                print("aiorobot top: no node found in the graph (is it running, and on this --connect / "
                      "--domain-id?)", file=sys.stderr)
                if args.json:
                    print(json.dumps(report, indent=1))
                return 1
            if args.json:
                print(json.dumps(report, indent=1))
            else:
                from rich.console import Console

                console = Console()
                if not console.is_terminal:  # a file or a pipe: wide enough that no name is cut
                    console = Console(width=200)
                console.print(render(report))
            return 0
        from rich.live import Live

        with Live(render(summarize({}, first, [])), auto_refresh=False, screen=False) as live:
            while True:
                await asyncio.sleep(args.interval)
                second, silent = await _reading(rt, node)
                live.update(render(summarize(first, second, silent)), refresh=True)
                first = second


def _f(value: float, digits: int = 2) -> str:
    return f"{value:.{digits}f}" if value else "-"


def render(report: dict[str, Any]) -> Any:
    """The report as rich tables: processes, entities, topics, culprits."""
    from rich.console import Group
    from rich.table import Table

    procs = Table(title="processes", title_justify="left", expand=False)
    for col in ("PID", "HOST", "CPU %", "THREADS", "NODES", "LATE PERIODS"):
        procs.add_column(col, justify="right" if col not in ("HOST", "NODES") else "left")
    for p in report["processes"]:
        procs.add_row(str(p["pid"]), p["host"], f"{p['cpu_percent']:.1f}", str(p["threads"]),
                      " ".join(p["nodes"]), str(p["late_periods"]))
    entities = Table(title="callbacks", title_justify="left")
    for col in ("NODE", "PID", "ENTITY", "CB/S", "P50 ms", "P99 ms", "MAX ms", "LATE P99 ms", "QUEUE", "DROPS", "STALLS"):
        entities.add_column(col, justify="left" if col in ("NODE", "ENTITY") else "right")
    for n in report["nodes"]:
        shown = [e for e in n["entities"] if e["callbacks"] or e["kind"] != "service"]
        for i, e in enumerate(shown or [{}]):
            if not e:
                entities.add_row(n["name"], str(n["pid"]), "(no callbacks)", *["-"] * 7, str(n["stalls"] or "-"))
                continue
            sub = e["kind"] == "subscription"
            label = e["name"]
            if label.startswith(n["name"] + "/"):
                label = "~" + label[len(n["name"]):]
            entities.add_row(
                n["name"] if i == 0 else "", str(n["pid"]) if i == 0 else "", f"{e['kind']} {label}",
                _f(e["callbacks_per_sec"], 1), _f(e["time_p50_ms"], 3), _f(e["time_p99_ms"], 3), _f(e["time_max_ms"], 3),
                _f(e.get("lateness_p99_ms", 0.0), 3),
                f"{e['queued']}/{e['depth']}" if sub else "", str(e["dropped"]) if sub else "",
                str(n["stalls"] or "-") if i == 0 else "",
            )
    topics = Table(title="topics", title_justify="left")
    for col in ("TOPIC", "OUT msg/s", "IN msg/s"):
        topics.add_column(col, justify="left" if col == "TOPIC" else "right")
    for t in report["topics"]:
        topics.add_row(t["topic"], _f(t["out_per_sec"], 1), _f(t["in_per_sec"], 1))
    parts: list[Any] = [procs, entities, topics]
    culprits = [(p["pid"], c) for p in report["processes"] for c in p["culprits"]]
    if culprits:
        table = Table(title="late priority periods: culprits", title_justify="left")
        for col in ("PID", "FUNCTION", "WHERE", "NODE / THREAD", "LATE", "TOTAL ms", "WORST ms"):
            table.add_column(col, justify="right" if col in ("PID", "LATE", "TOTAL ms", "WORST ms") else "left")
        for pid, c in sorted(culprits, key=lambda pc: -pc[1]["lateness_total_ms"]):
            table.add_row(str(pid), c["function"], c["where"], c["node"] or c["thread"], str(c["late_periods"]),
                          f"{c['lateness_total_ms']:.1f}", _f(c["lateness_max_ms"]))
        parts.append(table)
    if report["without_statistics"]:
        from rich.text import Text

        parts.append(Text("no statistics from: " + ", ".join(report["without_statistics"])
                          + " (nodes without parameter services, or not aiorobot)", style="dim"))
    return Group(*parts)
