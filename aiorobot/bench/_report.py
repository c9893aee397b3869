"""The benchmark's tables (rich), one per part, with reference rows and noise beside the figures."""

from __future__ import annotations

from typing import Any

__all__ = ["figure_table", "fit_table", "headline_table", "print_report", "render_report"]


def _f(value: Any, digits: int = 1) -> str:
    if value is None:
        return "-"
    if isinstance(value, bool):
        return str(value)
    if isinstance(value, int):
        return f"{value:,}"
    if isinstance(value, float):
        return f"{value:,.{digits}f}"
    return str(value)


#: The noise columns printed beside every row's figures.
NOISE_COLUMNS = ("steal %", "others %", "load")


def _noise(noise: dict[str, Any] | None) -> tuple[str, str, str]:
    if not noise:
        return "-", "-", "-"
    return _f(noise.get("steal_pct"), 1), _f(noise.get("others_pct"), 0), _f(noise.get("load1"), 2)


def _seed_table(part: dict[str, Any]) -> Any:
    from rich.table import Table

    cfg = part.get("config", {})
    title = (
        f"Seed experiment: {1e3 * cfg.get('control_period_sec', 0.02):g} ms control period, "
        f"{1e3 * cfg.get('work_sec', 0.15):g} ms perception every {1e3 * cfg.get('perception_period_sec', 0.1):g} ms, "
        f"{cfg.get('periods', '?')} periods after {cfg.get('warmup', '?')} warm-up (ms)"
    )
    table = Table(title=title, title_justify="left")
    for col in ("model", "work", "samples", "mean", "stdev", "p50", "p99", "max", ">1 ms", ">5 ms", *NOISE_COLUMNS):
        table.add_column(col, justify="left" if col in ("model", "work") else "right")
    for model, kinds in part.get("models", {}).items():
        for kind, res in kinds.items():
            if "error" in res:
                table.add_row(model, kind, res["error"], *[""] * 10)
                continue
            s = res["stats"]
            table.add_row(
                model,
                kind,
                _f(s["samples"]),
                _f(s["mean_ms"]),
                _f(s["stdev_ms"]),
                _f(s["p50_ms"]),
                _f(s["p99_ms"]),
                _f(s["max_ms"]),
                _f(s["late_1ms"]),
                _f(s["late_5ms"]),
                *_noise(res.get("noise")),
            )
    for name, ref in part.get("reference", {}).items():
        table.add_row(
            f"[dim]{name}[/dim]", "[dim]sleep[/dim]", "-", _f(ref.get("mean_ms")), _f(ref.get("stdev_ms")),
            "-", "-", _f(ref.get("max_ms")), "-", "-", "-", "-", "-",
        )
    table.caption = (
        "single: one asyncio loop, perception inline | threads: rclpy MultiThreadedExecutor(4) model, "
        "one group each | aiorobot: control on the priority loop, perception via Node.offload; aiorobot-rt: the same with "
        "Runtime(priority_realtime=True) (SCHED_FIFO). "
        "sleep releases the GIL, cpu holds it. Dim rows: the seed's published rclpy figures (its own script; here "
        "perception asks for 150 % of one thread, so one thread gives control a single tick per perception run)."
    )
    return table


def _timer_table(part: dict[str, Any]) -> Any:
    from rich.table import Table

    table = Table(
        title=f"Priority loop: {part.get('period_ms', 1.0):g} ms timer for {part.get('duration_sec', '?')} s (us)",
        title_justify="left",
    )
    for col in ("priority thread", "main loop", "error p50", "error p99", "error max", "late p50", "late p99", "late max",
                "overruns", "CPU % core", *NOISE_COLUMNS):
        table.add_column(col, justify="left" if col in ("main loop", "priority thread") else "right")
    for row in part.get("rows", []):
        e, late = row["period_error"], row["lateness_us"]
        floor = "floor" in row.get("runtime", "")
        table.add_row(
            ("[dim]floor: [/dim]" if floor else "") + row.get("scheduling", "-"),
            row["main_loop"],
            _f(e["p50_us"]), _f(e["p99_us"]), _f(e["max_us"]),
            _f(late["p50_us"]), _f(late["p99_us"]), _f(late["max_us"]),
            _f(row["overruns"]), _f(row["thread_cpu_pct"], 2), *_noise(row.get("noise")),
        )
    table.add_row("[dim]target[/dim]", "", "", "[dim]<= 100[/dim]", "[dim]<= 500[/dim]", "", "", "", "", "[dim]< 10[/dim]", "", "", "")
    table.caption = (
        "priority thread: Runtime() gives timerslack=1ns; Runtime(priority_realtime=True) adds SCHED_FIFO where permitted. "
        "floor: a bare Python thread sleeping to the same deadlines with clock_nanosleep (no loop): what the machine allows. "
        "error: |period - nominal|; late: start after deadline (Timer.stats); CPU: the priority thread's CPU time over wall time"
    )
    return table


def _latency_table(part: dict[str, Any]) -> Any:
    from rich.table import Table

    table = Table(title="Publish -> callback latency (us) and throughput", title_justify="left")
    for col in ("path", "payload", "p50", "p99", "max", "msgs/s", *NOISE_COLUMNS):
        table.add_column(col, justify="left" if col in ("path", "payload") else "right")
    for row in part.get("rows", []):
        if "note" in row:
            table.add_row(row["path"], row["payload"], "[dim]n/a[/dim]", "", "", "", "", "", "")
            continue
        lat = row["latency"]
        table.add_row(
            row["path"], row["payload"], _f(lat["p50_us"]), _f(lat["p99_us"]), _f(lat["max_us"]),
            _f(round(row["msgs_per_sec"])), *_noise(row.get("noise")),
        )
    notes = sorted({f"{r['path']}: {r['note']}" for r in part.get("rows", []) if "note" in r})
    table.caption = "; ".join(
        [
            *notes,
            "process pool: the round trip of await node.offload(echo, msg)",
            "targets: same loop p50 <= 10 us and >= 200k msgs/s, main -> priority p99 <= 100 us",
        ]
    )
    return table


def _cpu_table(part: dict[str, Any]) -> Any:
    from rich.table import Table

    table = Table(title="CPU cost: process CPU time / wall time", title_justify="left")
    for col in ("case", "% of a core", *NOISE_COLUMNS):
        table.add_column(col, justify="left" if col == "case" else "right")
    for row in part.get("rows", []):
        table.add_row(row["case"], _f(row["core_pct"], 2), *_noise(row.get("noise")))
    for name, pct in part.get("reference", {}).items():
        table.add_row(f"[dim]{name}[/dim]", f"[dim]{_f(pct)}[/dim]", "-", "-", "-")
    table.caption = "target: a 100 Hz publishing timer <= 2 % of a core"
    return table


def _tf_table(part: dict[str, Any]) -> Any:
    from rich.table import Table

    table = Table(title="tf: lookups and batch point transforms", title_justify="left")
    table.add_column("figure")
    table.add_column("value", justify="right")
    for key, value in part.items():
        if isinstance(value, dict):
            continue
        table.add_row(key, _f(value, 2))
    return table


def figure_table(title: str, columns: tuple[str, ...], rows: list[tuple[Any, ...]], *, caption: str | None = None) -> Any:
    """A table for a part's figures: the first column left-aligned, numbers formatted with ``_f``.

    What domain parts (sim, fusion, perception, ...) build their ``table(part)`` from.
    """
    from rich.table import Table

    table = Table(title=title, title_justify="left", caption=caption)
    for i, col in enumerate(columns):
        table.add_column(col, justify="left" if i == 0 else "right")
    for row in rows:
        table.add_row(*(cell if isinstance(cell, str) else _f(cell, 2) for cell in row))
    return table


_TABLES = {"seed": _seed_table, "timer": _timer_table, "latency": _latency_table, "cpu": _cpu_table, "tf": _tf_table}


def headline_table(doc: dict[str, Any]) -> Any:
    """The figure the benchmark exists for, printed first: control period p99 and max per executor model.

    ``None`` when the seed part did not run (``--only`` without it).
    """
    from rich.table import Table

    part = doc.get("parts", {}).get("seed")
    if not part or "error" in part:
        return None
    cfg = part.get("config", {})
    nominal = 1e3 * cfg.get("control_period_sec", 0.02)
    table = Table(
        title=f"Headline: {nominal:g} ms control period beside {1e3 * cfg.get('work_sec', 0.15):g} ms perception (ms)",
        title_justify="left",
        caption="perception that releases the GIL (sleep) or holds it (cpu); details in the seed table below",
    )
    table.add_column("model")
    kinds = sorted({kind for kinds in part.get("models", {}).values() for kind in kinds}, key=("sleep", "cpu").index)
    for kind in kinds:
        table.add_column(f"{kind} p99", justify="right")
        table.add_column(f"{kind} max", justify="right")
    for model, results in part.get("models", {}).items():
        cells = []
        for kind in kinds:
            stats = results.get(kind, {}).get("stats")
            cells += [_f(stats["p99_ms"]), _f(stats["max_ms"])] if stats else ["failed", ""]
        table.add_row(model, *cells)
    table.add_row("[dim]nominal[/dim]", *[f"[dim]{nominal:g}[/dim]"] * (2 * len(kinds)))
    return table


def render_report(doc: dict[str, Any]) -> list[Any]:
    """The renderables of a benchmark document: the headline, a header line, then one table per part."""
    from rich.text import Text

    meta = doc.get("meta", {})
    noise = meta.get("noise") or {}
    header = Text(
        f"aiorobot bench latency - {meta.get('date_utc', '?')} - {meta.get('cpus', '?')} CPUs, "
        f"Python {meta.get('python', '?')}, {meta.get('platform', '?')} - repeat {meta.get('repeat', 1)}"
        f"{' (median)' if meta.get('repeat', 1) > 1 else ''}{' - QUICK' if meta.get('quick') else ''} - "
        f"steal {_f(noise.get('steal_pct'))} %, other programs {_f(noise.get('others_pct'), 0)} %, "
        f"load {_f(noise.get('load1'), 2)}"
    )
    legend = Text(
        "Noise beside every row: steal % = CPU the VM host took; others % = machine CPU (all cores) used by "
        "other programs, forkserver-started pool workers included; load = 1-minute load average.",
        style="dim",
    )
    headline = headline_table(doc)
    out: list[Any] = [header, legend] if headline is None else [headline, header, legend]
    for name, part in doc.get("parts", {}).items():
        if "error" in part:
            out.append(Text(f"{name}: {part['error']}"))
            continue
        out.append(_table_for(name)(part))
    return out


def _table_for(name: str) -> Any:
    """The table builder of part ``name``: a built-in one, or the part module's own ``table(part)``.

    Parts added by domain packages (sim, fusion, perception, ...) keep their table beside their
    figures: the module named in ``PARTS`` provides ``table(part: dict) -> rich.table.Table``.
    """
    if name in _TABLES:
        return _TABLES[name]
    import importlib

    from ._runner import PARTS

    return importlib.import_module(PARTS[name]).table


def print_report(doc: dict[str, Any], console: Any = None) -> None:
    """Print the report to ``console`` (a rich Console; stdout by default), stacking tables too wide for it."""
    from rich.console import Console
    from rich.table import Table

    if console is None:
        console = Console()
        if not console.is_terminal:  # a file or a pipe: do not squeeze the tables into 80 columns
            console = Console(width=160)
    for item in render_report(doc):
        for piece in fit_table(item, console) if isinstance(item, Table) else [item]:
            console.print(piece)
        console.print()


#: A column of labels (model, path, ...) may wrap down to this many cells wide; figures never wrap.
_LABEL_MIN_WIDTH = 12


def fit_table(table: Any, console: Any) -> list[Any]:
    """``table`` as one or more tables that fit ``console.width`` without cutting a figure short.

    rich squeezes a wide table into a narrow terminal by truncating cells (``15…``), which turns
    figures into nonsense. A table that does not fit is stacked instead: its columns are dealt
    out, in order, to several tables that each repeat the first (label) column; the title stays
    on the first and the caption goes under the last. Labels may wrap; figures are never cut.
    """
    from rich.measure import Measurement
    from rich.table import Table

    width = console.width
    unbounded = console.options.update(width=10_000)
    if Measurement.get(console, unbounded, table).maximum <= width or len(table.columns) < 3:
        return [table]

    def natural(column: Any) -> int:
        cells = [column.header, *column.cells]
        return max(Measurement.get(console, unbounded, console.render_str(c) if isinstance(c, str) else c).maximum
                   for c in cells)

    # the leading left-aligned columns name a row (model, work); the right-aligned ones are its figures
    n_keys = 1
    while n_keys < len(table.columns) - 1 and table.columns[n_keys].justify == "left":
        n_keys += 1
    keys, rest = table.columns[:n_keys], table.columns[n_keys:]
    key_widths = [min(natural(key), max(_LABEL_MIN_WIDTH, width // (3 + n_keys))) for key in keys]
    room = width - sum(w + 3 for w in key_widths) - 1  # a column: its cells, two of padding, one border; one closing
    needs = [natural(column) + 3 for column in rest]
    groups = _deal(rest, needs, room)
    # as many tables as needed, but evenly filled: no last table holding a lone column
    share = -(-sum(needs) // len(groups))
    for target in range(share, room + 1):
        even = _deal(rest, needs, target)
        if len(even) == len(groups):
            groups = even
            break
    pieces = []
    for i, group in enumerate(groups):
        piece = Table(
            title=table.title if i == 0 else None,
            title_justify=table.title_justify,
            caption=table.caption if i == len(groups) - 1 else None,
        )
        for key, key_width in zip(keys, key_widths):
            piece.add_column(key.header, justify=key.justify, style=key.style, header_style=key.header_style,
                             max_width=key_width, overflow="fold")
        for column in group:
            piece.add_column(column.header, justify=column.justify, style=column.style,
                             header_style=column.header_style, no_wrap=True)
        for row in zip(*(list(c.cells) for c in (*keys, *group))):
            piece.add_row(*row)
        pieces.append(piece)
    return pieces


def _deal(columns: list[Any], needs: list[int], room: int) -> list[list[Any]]:
    """Columns in order into groups of at most ``room`` cells each (a wider column gets a group of its own)."""
    groups: list[list[Any]] = [[]]
    used = 0
    for column, need in zip(columns, needs):
        if groups[-1] and used + need > room:
            groups.append([])
            used = 0
        groups[-1].append(column)
        used += need
    return groups
