"""Write docs/api.md: the public API of ``aiorobot`` (and its subpackages) from the docstrings.

    python tools/gen_api_docs.py          # rewrite docs/api.md
    python tools/gen_api_docs.py --check  # exit 1 when docs/api.md is out of date

Each name in a package's ``__all__`` gets a heading, its signature, the first paragraph
of its docstring and, for classes, their public methods and properties with the first
line of each docstring.
"""

from __future__ import annotations

import argparse
import importlib
import inspect
import sys
from pathlib import Path

__all__ = ["PACKAGES", "render"]

ROOT = Path(__file__).resolve().parent.parent
OUT = ROOT / "docs" / "api.md"
#: the packages documented, in order (aiorobot's subpackages that users import by name)
PACKAGES = (
    "aiorobot", "aiorobot.launch", "aiorobot.tf", "aiorobot.message_filters", "aiorobot.lifecycle", "aiorobot.testing",
    "aiorobot.lowlevel", "aiorobot.control",
)


def _first_paragraph(obj: object) -> str:
    doc = inspect.getdoc(obj) or ""
    return doc.split("\n\n", 1)[0].strip()


def _signature(obj: object) -> str:
    try:
        return str(inspect.signature(obj))  # type: ignore[arg-type]
    except (TypeError, ValueError):
        return ""


def _members(cls: type) -> list[str]:
    lines = []
    for name, member in sorted(vars(cls).items()):
        if name.startswith("_"):
            continue
        if isinstance(member, property):
            summary = (_first_paragraph(member) or "").splitlines()[0:1]
            lines.append(f"- `{name}` (property){': ' + summary[0] if summary else ''}")
        elif inspect.isfunction(member) or isinstance(member, (staticmethod, classmethod)):
            fn = member.__func__ if isinstance(member, (staticmethod, classmethod)) else member
            summary = (_first_paragraph(fn) or "").splitlines()[0:1]
            lines.append(f"- `{name}{_signature(fn)}`{': ' + summary[0] if summary else ''}")
    return lines


def render() -> str:
    out = [
        "# aiorobot API reference",
        "",
        "Generated from the docstrings by `python tools/gen_api_docs.py`; do not edit by hand.",
        "`help(name)` shows the full documentation. The design contract is DESIGN.md; how the",
        "names map to rclpy is in [coming-from-rclpy.md](coming-from-rclpy.md).",
        "",
    ]
    for package in PACKAGES:
        module = importlib.import_module(package)  # every package is required: never write a truncated file
        names = list(getattr(module, "__all__", []))
        if not names:
            continue
        out += [f"## `{package}`", "", _first_paragraph(module), ""]
        for name in names:
            obj = getattr(module, name)
            kind = "class" if inspect.isclass(obj) else "function" if callable(obj) else "constant"
            out.append(f"### `{package}.{name}`")
            out.append("")
            if kind == "constant":
                out.append(f"constant: `{obj!r}`"[:300])
            else:
                out.append(f"{kind} `{name}{_signature(obj)}`")
            summary = _first_paragraph(obj) if kind != "constant" else ""
            if summary:
                out += ["", summary]
            if inspect.isclass(obj):
                members = _members(obj)
                if members:
                    out += [""] + members
            out.append("")
    return "\n".join(out).rstrip() + "\n"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="exit 1 when docs/api.md is out of date")
    args = parser.parse_args(argv)
    text = render()
    if args.check:
        if not OUT.exists() or OUT.read_text() != text:
            print(f"{OUT} is out of date: run python tools/gen_api_docs.py", file=sys.stderr)
            return 1
        return 0
    OUT.write_text(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
