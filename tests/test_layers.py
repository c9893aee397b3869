"""The import rules of docs/architecture.md, read from the code's own imports (tools/layers.py)."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent

#: rooms the core may import besides itself
CORE_MAY_IMPORT = {"msgs"}
#: what the issue names: the core imports none of these, ever
CORE_MUST_NOT_IMPORT = {"bag", "foxglove", "sim", "nav", "demo", "cli", "bench", "testing", "compat", "launch", "transport"}
#: production modules that still import the test kit (issue #28: being changed; remove each once it no longer does)
STILL_IMPORT_TESTING: set[str] = set()


@pytest.fixture(scope="module")
def layers():
    spec = importlib.util.spec_from_file_location("layers", ROOT / "tools" / "layers.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules["layers"] = module  # dataclasses look their module up while the class is built
    try:
        spec.loader.exec_module(module)
    finally:
        del sys.modules["layers"]
    return module


def _core_targets(layers, root=None) -> dict[str, list[str]]:
    out: dict[str, list[str]] = {}
    for imp in layers.collect(root):
        if layers.room_of(imp.module) == "_core" and layers.room_of(imp.target) not in (None, "_core"):
            out.setdefault(layers.room_of(imp.target), []).append(f"{imp.path}:{imp.line} imports {imp.target}")
    return out


def test_the_core_imports_no_application_extension_or_transport(layers) -> None:
    targets = _core_targets(layers)
    forbidden = {room: where for room, where in targets.items() if room in CORE_MUST_NOT_IMPORT}
    assert not forbidden, f"the core must not import these layers: {forbidden}"
    others = {room: where for room, where in targets.items() if room not in CORE_MAY_IMPORT}
    assert not others, f"the core imports only msgs (docs/architecture.md); found {others}"
    assert "msgs" in targets  # the collector does see the core's imports


def test_no_production_module_imports_the_test_kit(layers) -> None:
    users = {imp.module for imp in layers.collect() if layers.room_of(imp.target) == "testing"}
    users = {m for m in users if layers.room_of(m) != "testing"}
    assert users <= STILL_IMPORT_TESTING, f"production code imports aiorobot.testing: {sorted(users - STILL_IMPORT_TESTING)}"


def test_lazy_type_checking_and_front_door_imports_count(layers, tmp_path: Path) -> None:
    """A checkout whose core breaks every rule in a different way: each import is found."""
    pkg = tmp_path / "aiorobot"
    (pkg / "_core").mkdir(parents=True)
    (pkg / "sim").mkdir()
    (pkg / "__init__.py").write_text('_EXPORTS = {"World": "sim._world"}\n')
    (pkg / "sim" / "__init__.py").write_text("")
    (pkg / "sim" / "_world.py").write_text("World = object\n")
    (pkg / "_core" / "__init__.py").write_text("")
    (pkg / "_core" / "_runtime.py").write_text(
        "from typing import TYPE_CHECKING\n"
        "if TYPE_CHECKING:\n    from ..transport import _zenoh\n"
        "def load():\n    from .. import testing\n"
        "from aiorobot import World\n"
        "import aiorobot.bag._writer\n"
    )
    found = {room: len(where) for room, where in _core_targets(layers, tmp_path).items()}
    assert found == {"transport": 1, "testing": 1, "sim": 1, "bag": 1}


def test_the_architecture_page_shows_the_current_imports(layers) -> None:
    text = (ROOT / "docs" / "architecture.md").read_text()
    generated = layers.render()
    assert generated in text, "docs/architecture.md is out of date: run python tools/layers.py --write"
    assert "## Where extensions plug in" in text and "(docs/architecture.md)" in (ROOT / "README.md").read_text()


def test_no_import_runs_up_the_layers_or_closes_a_circle(layers) -> None:
    found = layers.summary()
    upward = [f"{a} -> {b} ({stmts[0].path}:{stmts[0].line})" for a, b, stmts in found["upward"]]
    assert not upward, f"imports that run up docs/architecture.md's layers: {upward}"
    assert not found["back"], f"import circles between rooms: {sorted(found['back'])}"
