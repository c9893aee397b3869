"""The package's layers, drawn from its own imports; writes the picture into docs/architecture.md.

    python tools/layers.py           # print the rooms, floors and upward imports
    python tools/layers.py --write   # rewrite the generated part of docs/architecture.md
    python tools/layers.py --check   # exit 1 when docs/architecture.md is out of date

A *room* is a subpackage of ``aiorobot`` (``_core``, ``bag``, ``perception``, ...) or a module
at the package root (``_config``); the package ``__init__`` is not a room: ``from aiorobot
import Node`` counts as an import of the module that defines ``Node`` (``_EXPORTS``). Every
``import`` statement counts, in functions and under ``TYPE_CHECKING`` too: a lazy import is
still a dependency. Rooms are stacked into *floors* from the imports alone: the rooms are put in
one order (Eades, Lin and Smyth's greedy heuristic, ties broken by name) so that as few imports
as possible point back up; those that do are the *back-edges*, and the floor of a room is one
above the highest room it imports along the remaining edges. The *layers* in ``LAYERS`` are the
intended design; an import from a lower layer into a higher one is listed as upward.
No dependency beyond the standard library: the picture is a mermaid graph in the markdown.
"""

from __future__ import annotations

import argparse
import ast
import sys
from collections import defaultdict
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

__all__ = ["LAYERS", "Imports", "collect", "edges", "layer_of", "render", "room_of", "rooms", "stack", "summary", "upward"]

ROOT = Path(__file__).resolve().parent.parent
DOC = ROOT / "docs" / "architecture.md"
#: folders at the top of the checkout that install as ``aiorobot.<folder>`` (setup.py's DOMAINS)
DOMAINS = ("perception", "control", "fusion")
BEGIN, END = "<!-- layers:begin (tools/layers.py --write) -->", "<!-- layers:end -->"

#: The intended layers, bottom first: a room may import its own layer and those below it.
LAYERS: tuple[tuple[str, tuple[str, ...]], ...] = (
    ("messages", ("msgs",)),
    ("core", ("_core", "parameters", "lowlevel")),  # lowlevel: the public seam over the core (#28 item 4)
    ("libraries", ("transport", "tf", "lifecycle", "message_filters")),
    ("domains", ("perception", "control", "fusion", "bag", "foxglove", "nav", "sim")),
    # launch composes a graph from a config file: any domain's nodes, the recorder, the bridge
    ("composition", ("launch", "_config", "_config_build")),
    ("applications", ("demo", "bench", "cli", "compat", "examples", "testing")),
)


@dataclass(frozen=True, slots=True)
class Imports:
    """One import statement of a production module: who imports what, where."""

    module: str  # importer, e.g. "aiorobot._core._runtime"
    target: str  # imported module, e.g. "aiorobot.msgs.rosgraph_msgs"
    path: str  # file relative to the checkout
    line: int


def _modules(root: Path) -> Iterator[tuple[str, Path, bool]]:
    """(dotted name, file, is a package __init__) of every production module under checkout ``root``."""
    bases = [(root / "aiorobot", "aiorobot")] + [(root / d, f"aiorobot.{d}") for d in DOMAINS]
    for base, prefix in bases:
        for path in sorted(base.rglob("*.py")):
            rel = path.relative_to(base).with_suffix("").parts
            if "__pycache__" in rel:
                continue
            is_pkg = rel[-1] == "__init__"
            parts = rel[:-1] if is_pkg else rel
            if prefix == "aiorobot" and parts and parts[0] in DOMAINS:
                continue
            yield ".".join((prefix, *parts)), path, is_pkg


def _exports(init: Path) -> dict[str, str]:
    """``aiorobot._EXPORTS``, read from the source (name -> defining module)."""
    for node in ast.parse(init.read_text()).body:
        if isinstance(node, (ast.Assign, ast.AnnAssign)):
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            if any(isinstance(t, ast.Name) and t.id == "_EXPORTS" for t in targets) and node.value is not None:
                table = ast.literal_eval(node.value)
                return {name: f"aiorobot.{module}" for name, module in table.items()}
    return {}


def collect(root: Path | None = None) -> list[Imports]:
    """Every import statement of aiorobot's production modules that names an aiorobot module."""
    root = root or ROOT
    modules = {name: (path, is_pkg) for name, path, is_pkg in _modules(root)}
    exports = _exports(root / "aiorobot" / "__init__.py")
    found: list[Imports] = []
    for name, (path, is_pkg) in modules.items():
        package = name if is_pkg else name.rpartition(".")[0]
        rel = str(path.relative_to(root))
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            targets: list[str] = []
            if isinstance(node, ast.Import):
                targets = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom):
                if node.level:
                    base = package.split(".")[: len(package.split(".")) - node.level + 1]
                    source = ".".join(base + ([node.module] if node.module else []))
                else:
                    source = node.module or ""
                for alias in node.names:
                    sub = f"{source}.{alias.name}"
                    if sub in modules:
                        targets.append(sub)  # from . import _offload
                    elif source == "aiorobot" and alias.name in exports:
                        targets.append(exports[alias.name])  # from aiorobot import Node
                    elif source == "aiorobot" and not alias.name.startswith("__"):
                        targets.append(sub)  # from aiorobot import testing (loaded on use)
                    else:
                        targets.append(source)
            for target in targets:
                if target == "aiorobot" or target.startswith("aiorobot."):
                    found.append(Imports(name, target, rel, node.lineno))
    return sorted(set(found), key=lambda i: (i.path, i.line, i.target))


def room_of(module: str) -> str | None:
    """``aiorobot._core._node`` -> ``_core``; ``aiorobot._config`` -> ``_config``; ``aiorobot`` -> None."""
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else None


def layer_of(room: str) -> int | None:
    for index, (_, rooms) in enumerate(LAYERS):
        if room in rooms:
            return index
    return None


def edges(imports: list[Imports]) -> dict[tuple[str, str], list[Imports]]:
    """(importing room, imported room) -> the statements behind that arrow."""
    out: dict[tuple[str, str], list[Imports]] = defaultdict(list)
    for imp in imports:
        a, b = room_of(imp.module), room_of(imp.target)
        if a and b and a != b:
            out[(a, b)].append(imp)
    return dict(out)


def rooms(root: Path | None = None) -> list[str]:
    return sorted({r for name, _, _ in _modules(root or ROOT) if (r := room_of(name))})


def stack(nodes: list[str], arrows: set[tuple[str, str]]) -> tuple[dict[str, int], set[tuple[str, str]]]:
    """Floors (0 = imports no other room) and the back-edges, as the module docstring defines them."""
    out_e = {n: {b for a, b in arrows if a == n} for n in nodes}
    in_e = {n: {a for a, b in arrows if b == n} for n in nodes}
    left = set(nodes)
    top: list[str] = []
    bottom: list[str] = []
    while left:
        changed = True
        while changed:
            changed = False
            for n in sorted(left):
                if not out_e[n] & left:  # imports nothing left: a sink goes to the bottom
                    bottom.insert(0, n)
                    left.discard(n)
                    changed = True
            for n in sorted(left):
                if not in_e[n] & left:  # nothing left imports it: a source goes to the top
                    top.append(n)
                    left.discard(n)
                    changed = True
        if left:
            best = max(sorted(left), key=lambda n: len(out_e[n] & left) - len(in_e[n] & left))
            top.append(best)
            left.discard(best)
    order = {n: i for i, n in enumerate(top + bottom)}  # top of the building first
    back = {(a, b) for a, b in arrows if order[a] > order[b]}
    floor: dict[str, int] = {}
    for n in sorted(nodes, key=lambda n: -order[n]):  # from the bottom up
        below = [floor[b] for a, b in arrows if a == n and (a, b) not in back]
        floor[n] = 1 + max(below) if below else 0
    return floor, back


def upward(arrows: dict[tuple[str, str], list[Imports]]) -> list[tuple[str, str, list[Imports]]]:
    """Imports from a room into a room of a higher layer in ``LAYERS`` (or a room with no layer)."""
    out = []
    for (a, b), stmts in sorted(arrows.items()):
        la, lb = layer_of(a), layer_of(b)
        if la is None or lb is None or lb > la:
            out.append((a, b, stmts))
    return out


def summary(root: Path | None = None) -> dict[str, object]:
    root = root or ROOT
    imports = collect(root)
    nodes = rooms(root)
    arrows = {ab: stmts for ab, stmts in edges(imports).items() if ab[1] in nodes}
    floor, back = stack(nodes, set(arrows))
    root_modules = sorted(p.stem for p in (root / "aiorobot").glob("*.py") if p.stem != "__init__")
    return {
        "rooms": nodes, "arrows": arrows, "floor": floor, "back": back, "root_modules": root_modules,
        "upward": upward(arrows),
    }


def render(root: Path | None = None) -> str:
    """The generated part of docs/architecture.md (between the markers)."""
    s = summary(root)
    nodes: list[str] = s["rooms"]  # type: ignore[assignment]
    arrows: dict[tuple[str, str], list[Imports]] = s["arrows"]  # type: ignore[assignment]
    floor: dict[str, int] = s["floor"]  # type: ignore[assignment]
    back: set[tuple[str, str]] = s["back"]  # type: ignore[assignment]
    ups = s["upward"]
    root_modules: list[str] = s["root_modules"]  # type: ignore[assignment]
    ident = {n: "r_" + n.strip("_") for n in nodes}
    lines = [BEGIN, "", "```mermaid", "flowchart BT"]
    for index, (layer, members) in enumerate(LAYERS):
        present = [n for n in members if n in nodes]
        if present:
            lines.append(f"  subgraph L{index}[\"{index}: {layer}\"]")
            lines += [f"    {ident[n]}[\"{n}\"]" for n in present]
            lines.append("  end")
    for n in nodes:
        if layer_of(n) is None:
            lines.append(f"  {ident[n]}[\"{n} (no layer)\"]")
    up = {(a, b) for a, b, _ in ups}  # type: ignore[misc]
    for a, b in sorted(arrows):
        lines.append(f"  {ident[a]} {'-. upward .->' if (a, b) in up else '-->'} {ident[b]}")
    lines += ["```", ""]
    lines += [
        f"Measured by `python tools/layers.py`: {len(root_modules)} modules at the package root "
        f"({', '.join(f'`{m}`' for m in root_modules) or 'none'}), {len(nodes)} rooms, "
        f"{len(arrows)} arrows, {max(floor.values()) + 1} floors, {len(back)} back-edges "
        f"({', '.join(f'{a} → {b}' for a, b in sorted(back)) or 'none'}).",
        "",
        "| floor | rooms (each imports only rooms on lower floors, back-edges aside) |",
        "|---|---|",
    ]
    for level in range(max(floor.values()), -1, -1):
        lines.append(f"| {level} | {', '.join(f'`{n}`' for n in nodes if floor[n] == level)} |")
    lines += ["", "Imports that run up the layers (to be removed):", ""]
    if not ups:
        lines.append("none")
    for a, b, stmts in ups:  # type: ignore[misc]
        where = ", ".join(f"`{path}`" for path in sorted({i.path for i in stmts}))  # no line numbers: they move
        lines.append(f"- `{a}` → `{b}`: {where}")
    lines += ["", END]
    return "\n".join(lines)


def _replace(text: str, generated: str) -> str:
    if BEGIN not in text or END not in text:
        raise SystemExit(f"{DOC}: expected the markers {BEGIN!r} and {END!r}, found none; add them where the picture goes")
    head, rest = text.split(BEGIN, 1)
    return head + generated + rest.split(END, 1)[1]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    mode = parser.add_mutually_exclusive_group()
    mode.add_argument("--write", action="store_true", help="rewrite the generated part of docs/architecture.md")
    mode.add_argument("--check", action="store_true", help="exit 1 when docs/architecture.md is out of date")
    parser.add_argument("--root", type=Path, default=None, help="measure another checkout (e.g. an older commit's export)")
    args = parser.parse_args(argv)
    generated = render(args.root.resolve() if args.root else None)
    if args.write or args.check:
        current = DOC.read_text()
        wanted = _replace(current, generated)
        if args.check:
            if wanted != current:
                print(f"{DOC.relative_to(ROOT)} is out of date: run python tools/layers.py --write", file=sys.stderr)
                return 1
            return 0
        DOC.write_text(wanted)
        return 0
    print(generated)
    return 0


if __name__ == "__main__":
    sys.exit(main())
