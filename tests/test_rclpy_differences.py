"""docs/rclpy-differences.md and the code's ``rclpy difference:`` docstring markers stay in sync.

Every public object (a name a public aiorobot module exports, or a public member
of such a class) whose docstring has a line starting ``rclpy difference:`` has a
``## <aiorobot qualified name>`` section in the document, and every such section
names an object that exists and carries the marker. Sections may be added by
anyone, in any order; the headings are the contract.
"""

from __future__ import annotations

import importlib
import inspect
import pkgutil
import re
from pathlib import Path
from typing import Any

import aiorobot

DOC = Path(__file__).resolve().parents[1] / "docs" / "rclpy-differences.md"
MARKER = "rclpy difference:"
HEADING = re.compile(r"^## (?P<name>\S+)\s*$")


def has_marker(obj: Any) -> bool:
    doc = getattr(obj, "__doc__", None)
    if not isinstance(doc, str):
        return False
    return any(line.strip().startswith(MARKER) for line in inspect.cleandoc(doc).splitlines())


def identity(obj: Any) -> Any:
    return getattr(obj, "__func__", obj)


def public_modules() -> list[Any]:
    """aiorobot and every module under it with no ``_``-prefixed part (the public front doors).

    Subpackages installed from elsewhere in the repository (``aiorobot._SUBPACKAGES``,
    e.g. ``aiorobot.control`` from ``control/``) are walked too.
    """
    roots = [("aiorobot.", list(aiorobot.__path__))]
    for name in sorted(getattr(aiorobot, "_SUBPACKAGES", ())):
        package = importlib.import_module(f"aiorobot.{name}")
        roots.append((f"aiorobot.{name}.", list(getattr(package, "__path__", []))))
    names = {"aiorobot"} | {f"aiorobot.{n}" for n in getattr(aiorobot, "_SUBPACKAGES", ())}
    for prefix, path in roots:
        names.update(info.name for info in pkgutil.walk_packages(path, prefix))
    modules = []
    for name in sorted(names):
        if any(part.startswith("_") for part in name.split(".")):
            continue
        if name.startswith("aiorobot.msgs."):
            continue  # generated interface modules: no hand-written docstrings
        modules.append(importlib.import_module(name))
    return modules


def exported(module: Any) -> list[tuple[str, Any]]:
    names = getattr(module, "__all__", None)
    if names is None:
        names = [n for n in vars(module) if not n.startswith("_")]
    return [(n, getattr(module, n)) for n in names if hasattr(module, n)]


def marked_objects() -> dict[int, tuple[str, Any]]:
    """id(object) -> (one qualified name, object) for every public object carrying the marker."""
    found: dict[int, tuple[str, Any]] = {}
    for module in public_modules():
        for name, obj in exported(module):
            qualified = f"{module.__name__}.{name}"
            if has_marker(obj):
                found.setdefault(id(identity(obj)), (qualified, obj))
            if inspect.isclass(obj):
                for member_name in dir(obj):  # inherited members too (Node's mixins)
                    if member_name.startswith("_"):
                        continue
                    member = inspect.getattr_static(obj, member_name)
                    value = getattr(obj, member_name, member)
                    if type(value) is obj and getattr(value, "__doc__", None) == obj.__doc__:
                        continue  # an enum member or instance carrying its class's docstring: the class is listed
                    if has_marker(member) or has_marker(value):
                        found.setdefault(id(identity(value)), (f"{qualified}.{member_name}", value))
    return found


def resolve(qualified: str) -> Any:
    """The object ``aiorobot.pkg.Name.member`` names (longest importable module prefix, then attributes)."""
    parts = qualified.split(".")
    for cut in range(len(parts), 0, -1):
        try:
            obj: Any = importlib.import_module(".".join(parts[:cut]))
        except ImportError:
            continue
        for attr in parts[cut:]:
            obj = getattr(obj, attr)
        return obj
    raise ImportError(qualified)


def sections() -> dict[str, str]:
    """Heading name -> body text of every ``## name`` section of the document."""
    out: dict[str, str] = {}
    current = None
    for line in DOC.read_text(encoding="utf-8").splitlines():
        m = HEADING.match(line)
        if m:
            current = m.group("name")
            out.setdefault(current, "")
        elif line.startswith("## "):
            raise AssertionError(f"{DOC.name}: heading {line!r} is not '## <aiorobot qualified name>'")
        elif current is not None:
            out[current] += line + "\n"
    return out


def test_every_section_names_an_existing_marked_object():
    problems = []
    for name, body in sections().items():
        if not name.startswith("aiorobot."):
            problems.append(f"{name}: expected an aiorobot qualified name (aiorobot.…)")
            continue
        try:
            obj = resolve(name)
        except (ImportError, AttributeError) as exc:
            problems.append(f"{name}: no such object ({exc})")
            continue
        if not has_marker(obj):
            problems.append(f"{name}: its docstring has no line starting {MARKER!r}")
        if not body.strip():
            problems.append(f"{name}: the section says nothing (what differs, and why)")
    assert not problems, "\n".join(problems)


def test_every_marked_object_has_a_section():
    documented = set()
    for name in sections():
        try:
            documented.add(id(identity(resolve(name))))
        except (ImportError, AttributeError):
            pass
    missing = sorted(q for key, (q, _) in marked_objects().items() if key not in documented)
    assert not missing, f"add a '## <name>' section to {DOC.name} for: " + ", ".join(missing)


def test_the_known_differences_are_marked():
    # the differences this document started with (the previous closing note); the sync tests keep them honest
    for name in (
        "aiorobot.message_filters.ApproximateTimeSynchronizer",
        "aiorobot.ActionServer",
        "aiorobot.ActionClient.send_goal",
        "aiorobot.tf.Buffer.wait_for_transform",
        "aiorobot.lifecycle.LifecycleNode.on_shutdown",
        "aiorobot.control.GoToGoalController",
        "aiorobot.control.PurePursuitController",
    ):
        assert has_marker(resolve(name)), name
        assert name in sections(), name
