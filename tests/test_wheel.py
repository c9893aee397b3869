"""The built wheel carries every file the package needs, not only the Python modules.

The suite runs from an editable install, where a data file missing from the wheel goes unnoticed
(the built-in worlds once did). This test builds the wheel as a user's ``pip install .`` does and
compares its file list with the tracked files under each package folder.
"""

from __future__ import annotations

import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
#: install location -> folder in the checkout (pyproject's package-dir)
PACKAGE_FOLDERS = {"aiorobot": "aiorobot", "aiorobot/perception": "perception", "aiorobot/control": "control", "aiorobot/fusion": "fusion"}


def tracked_files(*folders: str) -> list[str]:
    return subprocess.run(["git", "ls-files", *folders], cwd=ROOT, capture_output=True, text=True, check=True).stdout.split()


def tracked_package_files() -> set[str]:
    """Every file git tracks under a package folder, named as it lands in site-packages."""
    installed = set()
    for path in tracked_files(*PACKAGE_FOLDERS.values()):
        folder, _, rest = path.partition("/")
        target = next(dest for dest, src in PACKAGE_FOLDERS.items() if src == folder)
        installed.add(f"{target}/{rest}")
    return installed


@pytest.fixture(scope="module")
def wheel_files(tmp_path_factory) -> set[str]:
    if not (ROOT / ".git").exists():
        pytest.skip("needs a git checkout to know which files are tracked")
    # Build from a copy of the tracked files, as from a fresh clone: a checkout's leftover
    # aiorobot.egg-info/SOURCES.txt would otherwise add files the configuration itself leaves out.
    source = tmp_path_factory.mktemp("source")
    for path in tracked_files():
        if (ROOT / path).is_file():
            (source / path).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(ROOT / path, source / path)
    out = tmp_path_factory.mktemp("wheel")
    subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "--no-deps", "--quiet", "--wheel-dir", str(out), str(source)],
        check=True, capture_output=True, text=True, timeout=50,
    )
    (wheel,) = out.glob("aiorobot-*.whl")
    with zipfile.ZipFile(wheel) as archive:
        return {name for name in archive.namelist() if ".dist-info/" not in name}


@pytest.mark.timeout(60)
def test_wheel_holds_every_tracked_file_of_the_packages(wheel_files):
    missing = sorted(tracked_package_files() - wheel_files)
    assert missing == [], f"files in the source tree but not in the wheel: {missing}"


@pytest.mark.timeout(60)
def test_wheel_holds_the_data_the_first_command_needs(wheel_files):
    needed = {
        "aiorobot/sim/worlds/warehouse.yaml", "aiorobot/sim/worlds/warehouse.pgm",
        "aiorobot/sim/worlds/box.yaml", "aiorobot/examples/default.toml", "aiorobot/py.typed",
    }
    assert needed <= wheel_files
    assert any(name.endswith(".msg") for name in wheel_files)
    assert not any("__pycache__" in name or name.endswith((".nbi", ".nbc")) for name in wheel_files)
