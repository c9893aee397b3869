"""Package list and package data for setuptools.

The three domain folders (``perception/``, ``control/``, ``fusion/``) sit at the
top of the repository but install as subpackages of ``aiorobot`` through the
``package-dir`` mapping in pyproject.toml; ``find_packages`` cannot see that
mapping, so the package list is assembled here.

Package data is every non-Python file under a package, including those in
plain folders that are not packages themselves (``aiorobot/sim/worlds/``):
setuptools' ``package-data`` globs never reach into such a folder unless told
to, which once left the built-in worlds out of the wheel. tests/test_wheel.py
builds the wheel and compares its file list with this tree.
"""
from __future__ import annotations

import os

from setuptools import find_packages, setup

DOMAINS = ("perception", "control", "fusion")
SKIPPED_DIRS = {"__pycache__"}
SKIPPED_SUFFIXES = (".py", ".pyc", ".pyo", ".nbi", ".nbc")


def package_dirs() -> dict[str, str]:
    """Every package's dotted name -> its folder in this checkout."""
    dirs = {name: name.replace(".", "/") for name in find_packages(include=["aiorobot", "aiorobot.*"])}
    for folder in DOMAINS:
        dirs[f"aiorobot.{folder}"] = folder
        for sub in find_packages(folder):
            dirs[f"aiorobot.{folder}.{sub}"] = os.path.join(folder, *sub.split("."))
    return dirs


def data_files(folder: str) -> list[str]:
    """Non-Python files of the package in ``folder``, relative to it, down through non-package folders."""
    found = []
    for root, subdirs, files in os.walk(folder):
        if root != folder and os.path.exists(os.path.join(root, "__init__.py")):
            subdirs[:] = []  # a subpackage lists its own data
            continue
        subdirs[:] = sorted(d for d in subdirs if d not in SKIPPED_DIRS and not d.startswith("."))
        found += [os.path.relpath(os.path.join(root, f), folder) for f in files if not f.endswith(SKIPPED_SUFFIXES)]
    return sorted(found)


dirs = package_dirs()
setup(packages=sorted(dirs), package_data={name: data_files(folder) for name, folder in dirs.items()})
