"""List the places where extensions reach into private members of the core's Runtime and Node.

    python tools/private_reaches.py      # one line per reach, then the total

A private member is a ``_name`` (not ``__dunder__``) that ``Runtime``, ``Node`` or a mixin of
``Node`` defines: a method, or an attribute assigned on ``self``. A reach is ``x._name`` in an
extension package with ``_name`` such a member, except ``self._name`` inside a class that defines
``_name`` itself (its own member) and ``loop._name`` (asyncio's loops, not ours). Extensions
should use ``aiorobot.lowlevel`` and the public API instead (issue #28).
"""

from __future__ import annotations

import ast
import sys
from collections.abc import Iterator
from pathlib import Path

__all__ = ["CORE_CLASSES", "EXTENSIONS", "core_private_members", "reaches"]

ROOT = Path(__file__).resolve().parent.parent
#: module file name -> classes whose private members count (searched in aiorobot/ and aiorobot/_core/)
CORE_CLASSES = {
    "_runtime.py": ("Runtime",),
    "_node.py": ("Node",),
    "_node_parameters.py": ("NodeParametersMixin",),
    "_node_graph.py": ("NodeGraphMixin",),
}
#: the extension packages, relative to the repository root
EXTENSIONS = (
    "aiorobot/bag", "aiorobot/foxglove", "aiorobot/compat", "aiorobot/sim", "aiorobot/nav", "aiorobot/demo",
    "aiorobot/cli", "aiorobot/bench", "perception", "control", "fusion",
)


def _members(cls: ast.ClassDef) -> set[str]:
    out: set[str] = set()
    for item in cls.body:
        if isinstance(item, (ast.FunctionDef, ast.AsyncFunctionDef)):
            out.add(item.name)
        elif isinstance(item, ast.Assign):
            out |= {t.id for t in item.targets if isinstance(t, ast.Name)}
        elif isinstance(item, ast.AnnAssign) and isinstance(item.target, ast.Name):
            out.add(item.target.id)
    for node in ast.walk(cls):
        if (
            isinstance(node, ast.Attribute)
            and isinstance(node.ctx, ast.Store)
            and isinstance(node.value, ast.Name)
            and node.value.id == "self"
        ):
            out.add(node.attr)
    return out


def core_private_members(root: Path = ROOT) -> set[str]:
    found: set[str] = set()
    for filename, classes in CORE_CLASSES.items():
        candidates = [root / "aiorobot" / filename, root / "aiorobot" / "_core" / filename]
        path = next((p for p in candidates if p.exists()), None)
        if path is None:
            raise FileNotFoundError(f"private_reaches: expected {filename} in aiorobot/ or aiorobot/_core/, found neither")
        for node in ast.parse(path.read_text()).body:
            if isinstance(node, ast.ClassDef) and node.name in classes:
                found |= {m for m in _members(node) if m.startswith("_") and not m.startswith("__")}
    return found


def reaches(root: Path = ROOT) -> Iterator[tuple[str, int, str]]:
    """``(path, line, expression)`` for every reach, in file order."""
    private = core_private_members(root)

    def visit(node: ast.AST, own: set[str]) -> Iterator[tuple[int, str]]:
        if isinstance(node, ast.ClassDef):
            own = _members(node)
        if isinstance(node, ast.Attribute) and node.attr in private:
            receiver = node.value.id if isinstance(node.value, ast.Name) else None
            if not (receiver in ("self", "cls") and node.attr in own) and receiver != "loop":
                yield node.lineno, ast.unparse(node)
        for child in ast.iter_child_nodes(node):
            yield from visit(child, own)

    for package in EXTENSIONS:
        for path in sorted((root / package).rglob("*.py")):
            for line, text in visit(ast.parse(path.read_text()), set()):
                yield str(path.relative_to(root)), line, text


def main() -> int:
    found = list(reaches(Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT))
    for path, line, text in found:
        print(f"{path}:{line}: {text}")
    print(f"{len(found)} reaches into private members of Runtime/Node from {', '.join(EXTENSIONS)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
